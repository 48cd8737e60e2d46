// A camera as COLMAP stores it: model id, image size, parameter vector.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace portcal {

using camera_t = uint32_t;
constexpr camera_t kInvalidCameraId = static_cast<camera_t>(-1);

struct Camera {
  camera_t camera_id = kInvalidCameraId;
  int model_id = 0;
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;
  bool has_prior_focal_length = false;

  // Builds a camera with COLMAP's default parameters for this focal length.
  static Camera FromModelName(const std::string& model_name, double focal_length, uint64_t width,
                              uint64_t height);

  std::string ModelName() const;
  std::string ParamsInfo() const;
  // Throws InputError (prefixed by `context`, e.g. a file name) if the model
  // is unknown, the parameter count is wrong, a parameter is not finite, a
  // focal length is not positive or a side of the image is not in
  // [1, 65535] px.
  void Validate(const std::string& context) const;

  double MeanFocalLength() const;
  double PrincipalPointX() const;
  double PrincipalPointY() const;

  // Point in the camera frame -> pixel (COLMAP convention). nullopt behind the
  // camera.
  std::optional<Eigen::Vector2d> ImgFromCam(const Eigen::Vector3d& point_in_cam) const;
  // Pixel -> ray direction (u, v, 1) in the camera frame. nullopt where the
  // distortion cannot be inverted.
  std::optional<Eigen::Vector3d> CamFromImg(const Eigen::Vector2d& pixel) const;
};

}  // namespace portcal
