// The list of COLMAP 3.8's camera models and runtime look-ups over it.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/camera/models/fisheye.h"
#include "colmap_ext/camera/models/fov.h"
#include "colmap_ext/camera/models/opencv.h"
#include "colmap_ext/camera/models/pinhole.h"
#include "colmap_ext/camera/models/radial.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/type_list.h"

namespace portcal {

// In COLMAP's id order (SIMPLE_PINHOLE 0 ... THIN_PRISM_FISHEYE 10).
using CameraModelList =
    TypeList<SimplePinholeModel, PinholeModel, SimpleRadialModel, RadialModel, OpenCVModel,
             OpenCVFisheyeModel, FullOpenCVModel, FOVModel, SimpleRadialFisheyeModel,
             RadialFisheyeModel, ThinPrismFisheyeModel>;

constexpr int kNumCameraModels = CameraModelList::kSize;

// Calls f(Model{}) for the model with this id; throws InputError naming the id
// when there is none.
template <typename F>
void VisitCameraModel(int model_id, F&& f) {
  if (!VisitModelById(CameraModelList{}, model_id, std::forward<F>(f))) {
    throw InputError("unknown camera model id " + std::to_string(model_id) +
                     " (COLMAP 3.8 knows ids 0 to 10)");
  }
}

bool ExistsCameraModelWithId(int model_id);
bool ExistsCameraModelWithName(const std::string& model_name);
// Throws InputError listing the valid names.
int CameraModelNameToId(const std::string& model_name);
std::string CameraModelIdToName(int model_id);
int CameraModelNumParams(int model_id);
std::string CameraModelParamsInfo(int model_id);
std::vector<int> CameraModelFocalLengthIdxs(int model_id);
std::vector<int> CameraModelPrincipalPointIdxs(int model_id);
std::vector<int> CameraModelExtraParamsIdxs(int model_id);
// Built on the equidistant angle (OPENCV_FISHEYE and the other *_FISHEYE).
bool CameraModelIsFisheye(int model_id);
std::vector<double> CameraModelInitializeParams(int model_id, double focal_length, int width,
                                                int height);
// "SIMPLE_PINHOLE, PINHOLE, ..." for help texts and errors.
std::string CameraModelNames();

}  // namespace portcal
