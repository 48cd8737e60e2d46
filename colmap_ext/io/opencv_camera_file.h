// Export of a camera to the two files robotics code reads most: OpenCV's
// FileStorage YAML (camera_matrix, distortion_coefficients, as
// cv::FileStorage writes them) and ROS's camera_info YAML (the format of
// camera_calibration_parsers, e.g. ../shared/datasets/real-dome/air_ost.yaml).
// Both use OpenCV's pixel convention: cx, cy = COLMAP's - 0.5.
//
// Models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV (plumb_bob,
// k1 k2 p1 p2 k3), FULL_OPENCV (rational_polynomial, 8 coefficients) and
// OPENCV_FISHEYE (cv::fisheye / ROS "equidistant", k1..k4). The others throw
// InputError naming the nearest exportable model.
#pragma once

#include <filesystem>
#include <string>

#include "colmap_ext/camera/camera.h"

namespace portcal {

// Both write atomically.
void WriteOpenCvCameraYaml(const Camera& camera, const std::filesystem::path& path);
void WriteRosCameraInfoYaml(const Camera& camera, const std::string& camera_name,
                            const std::filesystem::path& path);

}  // namespace portcal
