// ArUco markers in an image, as the auto-calibration uses them: detected
// with OpenCV, corners refined by edge fits, in COLMAP pixels; and the
// feature mask's test around a marker.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "colmap_ext/feature/marker_detection.h"

namespace portcal {

// The ArUco markers of `dictionary` in an 8-bit gray image, corners in
// COLMAP pixels and OpenCV's order (sub-pixel, contour refinement).
std::vector<MarkerDetection> DetectArucoMarkers(const cv::Mat& gray, const std::string& dictionary);

// Whether `xy` lies inside the marker quad scaled about its centroid.
bool InsideEnlargedQuad(const std::array<Eigen::Vector2d, 4>& quad, double factor,
                        const Eigen::Vector2d& xy);

}  // namespace portcal
