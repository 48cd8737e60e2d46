#include "database/feature_types.h"

#include <cmath>

namespace portcal {

FeatureKeypoint FeatureKeypoint::FromScaleOrientation(float x, float y,
                                                      float scale,
                                                      float orientation) {
  FeatureKeypoint keypoint;
  keypoint.x = x;
  keypoint.y = y;
  const float c = std::cos(orientation), s = std::sin(orientation);
  keypoint.a11 = scale * c;
  keypoint.a12 = -scale * s;
  keypoint.a21 = scale * s;
  keypoint.a22 = scale * c;
  return keypoint;
}

float FeatureKeypoint::ComputeScale() const {
  return 0.5f * (std::sqrt(a11 * a11 + a21 * a21) +
                 std::sqrt(a12 * a12 + a22 * a22));
}

float FeatureKeypoint::ComputeOrientation() const {
  return std::atan2(a21, a11);
}

TwoViewGeometry TwoViewGeometry::Inverse() const {
  TwoViewGeometry inverse = *this;
  inverse.F = F.transpose();
  inverse.E = E.transpose();
  if (H.determinant() != 0) inverse.H = H.inverse();
  inverse.cam2_from_cam1 = cam2_from_cam1.Inverse();
  for (FeatureMatch& match : inverse.inlier_matches) {
    std::swap(match.point2D_idx1, match.point2D_idx2);
  }
  return inverse;
}

bool SwapImagePair(image_t image_id1, image_t image_id2) {
  return image_id1 > image_id2;
}

image_pair_t ImagePairToPairId(image_t image_id1, image_t image_id2) {
  if (SwapImagePair(image_id1, image_id2)) std::swap(image_id1, image_id2);
  return static_cast<image_pair_t>(kMaxNumImages) * image_id1 + image_id2;
}

void PairIdToImagePair(image_pair_t pair_id, image_t* image_id1,
                       image_t* image_id2) {
  *image_id2 = static_cast<image_t>(pair_id % kMaxNumImages);
  *image_id1 = static_cast<image_t>((pair_id - *image_id2) / kMaxNumImages);
}

std::optional<Eigen::Vector3d> DatabaseImage::PriorPosition() const {
  if (cam_from_world_prior) return cam_from_world_prior->Inverse().translation;
  return position_prior;
}

}  // namespace portcal
