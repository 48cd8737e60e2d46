#include "database/feature_types.h"

#include <cmath>

namespace portcal {

bool SwapImagePair(image_t image_id1, image_t image_id2) { return image_id1 > image_id2; }

image_pair_t ImagePairToPairId(image_t image_id1, image_t image_id2) {
  if (SwapImagePair(image_id1, image_id2)) std::swap(image_id1, image_id2);
  return static_cast<image_pair_t>(kMaxNumImages) * image_id1 + image_id2;
}

void PairIdToImagePair(image_pair_t pair_id, image_t* image_id1, image_t* image_id2) {
  *image_id2 = static_cast<image_t>(pair_id % kMaxNumImages);
  *image_id1 = static_cast<image_t>((pair_id - *image_id2) / kMaxNumImages);
}

std::optional<Eigen::Vector3d> DatabaseImage::PriorPosition() const {
  if (cam_from_world_prior) return cam_from_world_prior->Inverse().translation;
  return position_prior;
}

}  // namespace portcal
