// The marker-corner refinement the auto-calibration's feature masker uses:
// along each side, the edge is located at many points where the profile
// across it crosses halfway between the dark border and the light
// surround, a curve (quadratic across a long side) is fitted through those
// points, and each corner is the intersection of its two sides' curves.
// Less accurate than fitting the edges to the pixels
// (marker_edge_refinement.h: median 0.026 against 0.017 px on rendered
// ArUco grids, and pixels off on markers foreshortened to modules of 2-4
// px), but the auto-calibration's mapper is sensitive to which marker
// corners it is given: with the pixel fit, one view of a three-face target
// was registered with its markers 700-6000 px off and other renders
// settled in other solutions (docs/benchmarks_target_detection.md). It stays here until the
// mapper checks poses against the markers.
#pragma once

#include <array>
#include <opencv2/core.hpp>

#include "pipelines/markers/marker_edge_refinement.h"

namespace portcal {

// As RefineMarkerCorners (OpenCV pixel coordinates and corner order);
// `options.min_module_px` and `max_passes` are not used: one pass, the
// bands as wide as a module along the side.
bool RefineMarkerCornersByCrossings(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                                    std::array<cv::Point2d, 4>* corners);

}  // namespace portcal
