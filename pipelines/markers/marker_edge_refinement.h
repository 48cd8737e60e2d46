// Sub-pixel corners of a square marker from its four outer edges: each
// side's edge is fitted to the pixels of a band along it (within the dark
// border module inside and the light surround outside) as a blurred step
// integrated over each pixel's area, its offset a quadratic along the side
// (for the bend lens distortion and refraction give long edges), its blur
// and its two levels (each varying linearly along the side, for shading)
// fitted with it; each corner is the intersection of its two sides' curves,
// and the bands are laid again about those corners until they stay put.
// No level is read off a profile's ends, which the next module's blur
// reaches. Figures in docs/benchmarks_target_detection.md. A marker foreshortened to modules
// narrower than `min_module_px` across a side is refused: OpenCV's corners
// of such a marker can be pixels off, and the band would hold the bits.
#pragma once

#include <array>
#include <opencv2/core.hpp>

namespace portcal {

struct MarkerEdgeRefinementOptions {
  int bits_per_side = 4;             // marker bits per side (the border adds 2 modules)
  double end_margin = 0.15;          // fraction of each side left out at both ends
  double min_contrast = 12;          // gray levels between border and surround
  double max_corner_shift_px = 2.0;  // or a tenth of the side: larger moves are refused
  double min_module_px =
      2.5;             // a module's width across a side below which the edge cannot be fitted
  int max_passes = 3;  // bands laid again about the fitted corners
};

// `corners`: OpenCV pixel coordinates, OpenCV's order (clockwise from the
// marker's top-left). Returns false (corners untouched) where a side
// cannot be fitted (too narrow across, too faint, leaving the image) or a
// corner would move further than `max_corner_shift_px`.
bool RefineMarkerCorners(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                         std::array<cv::Point2d, 4>* corners);

}  // namespace portcal
