#include "pipelines/sfm/camera_change.h"

#include <algorithm>
#include <limits>

namespace portcal {

double MaxImageShiftPx(const HousedCamera& before, const HousedCamera& after, double depth_m) {
  // A 9 x 9 grid from corner to corner (half a pixel in): the image's edges
  // are where distortion and a port's tilt move it most.
  constexpr int kGrid = 9;
  const double width = static_cast<double>(before.camera.width);
  const double height = static_cast<double>(before.camera.height);
  double max_shift = 0;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      const Eigen::Vector2d pixel(0.5 + (width - 1) * i / (kGrid - 1),
                                  0.5 + (height - 1) * j / (kGrid - 1));
      const auto ray = before.Unproject(pixel);
      if (!ray || !(ray->direction.z() > 0)) return std::numeric_limits<double>::infinity();
      const Eigen::Vector3d point =
          ray->origin + (depth_m - ray->origin.z()) / ray->direction.z() * ray->direction;
      const auto seen = after.Project(point);
      if (!seen) return std::numeric_limits<double>::infinity();
      max_shift = std::max(max_shift, (*seen - pixel).norm());
    }
  }
  return max_shift;
}

double MedianSceneDepth(const Reconstruction& r, int max_samples) {
  std::vector<double> depths;
  const size_t stride = std::max<size_t>(1, r.points().size() / std::max(1, max_samples));
  size_t k = 0;
  for (const auto& [id, point] : r.points()) {
    if (k++ % stride != 0 || point.track.empty()) continue;
    const double z = (r.poses().at(point.track.front().image_id) * point.xyz).z();
    if (z > 0) depths.push_back(z);
  }
  if (depths.empty()) return 0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

}  // namespace portcal
