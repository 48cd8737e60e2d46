// Sub-pixel corners of a square marker from its four outer edges: along
// each side, the edge is located at many points where the profile across it
// crosses halfway between the dark border and the light surround, a curve
// (quadratic across the side, for the bend lens distortion and refraction
// give long edges) is fitted through those points, and each corner is the
// intersection of its two sides' curves. A symmetric blur leaves the half-level crossing of a
// straight edge in place, so the corners carry no blur-dependent bias --
// unlike the corner detectors OpenCV's ArUco module offers, whose corners
// of a blurred marker sit ~0.1 px (cornerSubPix) to ~0.6 px (contour lines)
// inside the true outline (measured on the shared renders).
#pragma once

#include <array>
#include <opencv2/core.hpp>

namespace portcal {

struct MarkerEdgeRefinementOptions {
  int bits_per_side = 4;        // marker bits per side (the border adds 2 modules)
  double end_margin = 0.15;     // fraction of each side left out at both ends
  double min_contrast = 12;     // gray levels between border and surround
  double max_corner_shift_px = 2.0;  // or a tenth of the side: larger moves are refused
};

// `corners`: OpenCV pixel coordinates, OpenCV's order (clockwise from the
// marker's top-left). Returns false (corners untouched) where a side has
// too few edge points.
bool RefineMarkerCorners(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                         std::array<cv::Point2d, 4>* corners);

}  // namespace portcal
