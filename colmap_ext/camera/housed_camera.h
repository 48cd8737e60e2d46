// A camera with its housing, if it has one: what the pipelines project and
// back-project through (in air when `housing` is empty).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <map>
#include <optional>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {

struct HousedCamera {
  Camera camera;
  std::optional<Housing> housing;

  // The housing or nullptr (in air), for the free functions of housing.h.
  const Housing* HousingOrNull() const { return housing ? &*housing : nullptr; }
  // Point in the camera frame -> pixel (ProjectPoint).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_cam) const {
    return ProjectPoint(camera, HousingOrNull(), point_in_cam);
  }
  // Pixel -> ray in water, or in air without a housing (UnprojectPixel).
  std::optional<Ray3d> Unproject(const Eigen::Vector2d& pixel) const {
    return UnprojectPixel(camera, HousingOrNull(), pixel);
  }
};

// Whether any of `cameras` is behind a housing (refraction then sets the
// model's scale, which in air is a gauge).
inline bool AnyHoused(const std::map<camera_t, HousedCamera>& cameras) {
  return std::any_of(cameras.begin(), cameras.end(),
                     [](const auto& entry) { return entry.second.housing.has_value(); });
}

}  // namespace portcal
