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

// True where the file is one of the two: OpenCV's FileStorage YAML (it
// starts with "%YAML:1.0") or a YAML file with a camera_matrix.
bool IsOpenCvOrRosCameraYaml(const std::filesystem::path& path);

// Reads either file back (OpenCV's, as cv::FileStorage or portcal writes it,
// or ROS camera_info, as camera_calibration_parsers write it). The COLMAP
// model is the one that holds the coefficients exactly: five plumb_bob /
// standard coefficients with k3 = 0 -> OPENCV, k3 != 0 -> FULL_OPENCV;
// eight (rational_polynomial) -> FULL_OPENCV; four "equidistant" / "fisheye"
// -> OPENCV_FISHEYE; none (all zero) -> PINHOLE. Throws InputError naming
// the file and the key that is missing or malformed.
Camera ReadOpenCvCameraYaml(const std::filesystem::path& path);

}  // namespace portcal
