// Reading back the stereo calibration.yaml stereo_calibrator writes: the
// two cameras (each with its housing, if any) and the relative pose, for
// the stages that use a calibrated rig (image_undistorter's rectified
// pairs).
#pragma once

#include <filesystem>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct StereoCalibrationFile {
  HousedCamera camera1, camera2;  // camera ids 1 and 2
  Rigid3d cam2_from_cam1;
};

// Whether `path` is a YAML file with a cam2_from_cam1 block (a stereo
// calibration rather than one camera's). False for files that do not parse.
bool IsStereoCalibrationFile(const std::filesystem::path& path);

// Throws InputError naming the file and the key at fault.
StereoCalibrationFile ReadStereoCalibrationFile(const std::filesystem::path& path);

}  // namespace portcal
