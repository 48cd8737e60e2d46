// One ArUco marker found in an image (portcal_marker_detections).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

namespace portcal {

struct MarkerDetection {
  std::string dictionary;  // e.g. DICT_4X4_50
  int marker_id = 0;
  std::array<Eigen::Vector2d, 4> corners;  // COLMAP pixels, OpenCV's order
};

}  // namespace portcal
