// Pictures of the views themselves, drawn on their images (when the report
// knows where they are: the calibrator's --image_path): the worst views
// with their corners and residual vectors, as mrcal's
// show-residuals-board-observation draws them, and every view as a
// thumbnail with its detected corners (OpenCV's drawChessboardCorners
// habit), so that a misdetection or a blurred view is seen at a glance.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "pipelines/report/calibration_pictures.h"

namespace portcal {

// The `count` kept views of highest RMS, each on its image (grey where the
// image cannot be read), the corners green and the residuals red,
// magnified so that the p95 residual is 20 px; named with their RMS.
cv::Mat WorstViewsPicture(const ViewsAtPoses& views, const std::filesystem::path& image_root,
                          int count = 3);

// Every view (at most 48, in order) as a 200 px wide thumbnail with its
// corners (green; grey for a dropped view) and its name; empty when no
// image could be read.
cv::Mat ThumbnailsPicture(const ViewsAtPoses& views, const std::filesystem::path& image_root);

}  // namespace portcal
