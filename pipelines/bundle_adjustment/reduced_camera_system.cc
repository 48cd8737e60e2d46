#include "pipelines/bundle_adjustment/reduced_camera_system.h"

#include <algorithm>
#include <vector>

namespace portcal {

size_t ReducedCameraSystemBlocks(const Reconstruction& reconstruction,
                                 const std::map<point3D_t, Eigen::Vector3d>& point_blocks,
                                 const std::function<bool(image_t)>& is_free) {
  std::map<image_t, std::vector<image_t>> neighbours;
  std::vector<image_t> track;
  for (const auto& [point_id, xyz] : point_blocks) {
    track.clear();
    for (const TrackElement& e : reconstruction.points().at(point_id).track) {
      if (is_free(e.image_id)) track.push_back(e.image_id);
    }
    for (const image_t a : track) {
      std::vector<image_t>& of_a = neighbours[a];
      for (const image_t b : track) {
        if (b != a) of_a.push_back(b);
      }
    }
  }
  size_t blocks = 0;
  for (auto& [image_id, of_image] : neighbours) {
    std::sort(of_image.begin(), of_image.end());
    blocks +=
        1 + static_cast<size_t>(std::unique(of_image.begin(), of_image.end()) - of_image.begin());
  }
  return blocks;
}

}  // namespace portcal
