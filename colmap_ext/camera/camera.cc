#include "colmap_ext/camera/camera.h"

#include <cmath>

#include "colmap_ext/camera/camera_models.h"

namespace portcal {

Camera Camera::FromModelName(const std::string& model_name, double focal_length, uint64_t width,
                             uint64_t height) {
  Camera camera;
  camera.model_id = CameraModelNameToId(model_name);
  camera.width = width;
  camera.height = height;
  camera.params = CameraModelInitializeParams(camera.model_id, focal_length,
                                              static_cast<int>(width), static_cast<int>(height));
  return camera;
}

std::string Camera::ModelName() const { return CameraModelIdToName(model_id); }

std::string Camera::ParamsInfo() const { return CameraModelParamsInfo(model_id); }

void Camera::Validate(const std::string& context) const {
  if (!ExistsCameraModelWithId(model_id)) {
    throw InputError(context + ": unknown camera model id " + std::to_string(model_id));
  }
  // No camera has a side beyond 65 535 px; a corrupted or hostile file that
  // claims one would make the stages allocate or loop over it for minutes.
  constexpr uint64_t kMaxImageSide = 65535;
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide) {
    throw InputError(context + ": image size " + std::to_string(width) + " x " +
                     std::to_string(height) + " px outside [1, " + std::to_string(kMaxImageSide) +
                     "] per side");
  }
  const int expected = CameraModelNumParams(model_id);
  if (static_cast<int>(params.size()) != expected) {
    throw InputError(context + ": camera model " + ModelName() + " takes " +
                     std::to_string(expected) + " parameters (" + ParamsInfo() + "), got " +
                     std::to_string(params.size()));
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) {
      throw InputError(context + ": camera parameter " + std::to_string(i) + " is not finite");
    }
  }
  for (const int idx : CameraModelFocalLengthIdxs(model_id)) {
    if (!(params[idx] > 0)) {
      throw InputError(context + ": focal length must be positive, got " +
                       std::to_string(params[idx]));
    }
  }
}

double Camera::MeanFocalLength() const {
  const std::vector<int> idxs = CameraModelFocalLengthIdxs(model_id);
  double sum = 0;
  for (const int idx : idxs) sum += params.at(idx);
  return sum / static_cast<double>(idxs.size());
}

double Camera::PrincipalPointX() const {
  return params.at(CameraModelPrincipalPointIdxs(model_id)[0]);
}

double Camera::PrincipalPointY() const {
  return params.at(CameraModelPrincipalPointIdxs(model_id)[1]);
}

std::optional<Eigen::Vector2d> Camera::ImgFromCam(const Eigen::Vector3d& point_in_cam) const {
  std::optional<Eigen::Vector2d> pixel;
  VisitCameraModel(model_id, [&](auto model) {
    using Model = decltype(model);
    PORTCAL_CHECK(static_cast<int>(params.size()) == Model::kNumParams);
    Eigen::Vector2d xy;
    if (Model::ImgFromCam(params.data(), point_in_cam.x(), point_in_cam.y(), point_in_cam.z(),
                          &xy.x(), &xy.y())) {
      pixel = xy;
    }
  });
  return pixel;
}

std::optional<Eigen::Vector3d> Camera::CamFromImg(const Eigen::Vector2d& pixel) const {
  std::optional<Eigen::Vector3d> ray;
  VisitCameraModel(model_id, [&](auto model) {
    using Model = decltype(model);
    PORTCAL_CHECK(static_cast<int>(params.size()) == Model::kNumParams);
    double u, v;
    if (Model::CamFromImg(params.data(), pixel.x(), pixel.y(), &u, &v)) {
      ray = Eigen::Vector3d(u, v, 1.0);
    }
  });
  return ray;
}

}  // namespace portcal
