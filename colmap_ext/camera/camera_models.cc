#include "colmap_ext/camera/camera_models.h"

namespace portcal {

bool ExistsCameraModelWithId(int model_id) {
  return VisitModelById(CameraModelList{}, model_id, [](auto) {});
}

bool ExistsCameraModelWithName(const std::string& model_name) {
  return VisitModelByName(CameraModelList{}, model_name, [](auto) {});
}

std::string CameraModelNames() { return ModelNames(CameraModelList{}); }

int CameraModelNameToId(const std::string& model_name) {
  int id = -1;
  if (!VisitModelByName(CameraModelList{}, model_name,
                        [&](auto model) { id = decltype(model)::kId; })) {
    throw InputError("unknown camera model '" + model_name + "' (expected one of " +
                     CameraModelNames() + ")");
  }
  return id;
}

std::string CameraModelIdToName(int model_id) {
  std::string name;
  VisitCameraModel(model_id, [&](auto model) { name = decltype(model)::kName; });
  return name;
}

int CameraModelNumParams(int model_id) {
  int n = 0;
  VisitCameraModel(model_id, [&](auto model) { n = decltype(model)::kNumParams; });
  return n;
}

std::string CameraModelParamsInfo(int model_id) {
  std::string info;
  VisitCameraModel(model_id, [&](auto model) { info = decltype(model)::kParamsInfo; });
  return info;
}

std::vector<int> CameraModelFocalLengthIdxs(int model_id) {
  std::vector<int> idxs;
  VisitCameraModel(model_id, [&](auto model) { idxs = decltype(model)::FocalLengthIdxs(); });
  return idxs;
}

std::vector<int> CameraModelPrincipalPointIdxs(int model_id) {
  std::vector<int> idxs;
  VisitCameraModel(model_id, [&](auto model) { idxs = decltype(model)::PrincipalPointIdxs(); });
  return idxs;
}

std::vector<int> CameraModelExtraParamsIdxs(int model_id) {
  std::vector<int> idxs;
  VisitCameraModel(model_id, [&](auto model) { idxs = decltype(model)::ExtraParamsIdxs(); });
  return idxs;
}

bool CameraModelIsFisheye(int model_id) {
  bool fisheye = false;
  VisitCameraModel(model_id, [&](auto model) { fisheye = decltype(model)::kFisheye; });
  return fisheye;
}

std::vector<double> CameraModelInitializeParams(int model_id, double focal_length, int width,
                                                int height) {
  std::vector<double> params;
  VisitCameraModel(model_id, [&](auto model) {
    params = decltype(model)::InitializeParams(focal_length, width, height);
  });
  return params;
}

}  // namespace portcal
