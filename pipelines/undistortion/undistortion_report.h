// What image_undistorter says about each camera: the virtual pinhole, how
// its design depth was chosen and the approximation's error over the depth
// range (undistortion.txt for people, undistortion.yaml for programs,
// report.html with an error map per depth).
#pragma once

#include <string>
#include <vector>

#include "pipelines/report/html_report.h"
#include "pipelines/undistortion/approximation_error.h"

namespace portcal {

struct CameraUndistortion {
  VirtualPinhole pinhole;
  DepthRange range;          // the depths the error was measured over
  std::string depth_choice;  // how the design depth and range were chosen, in words
  ApproximationError error;
  // Rectified stereo: the other camera's id and the baseline (m); 0 and 0
  // elsewhere.
  camera_t stereo_partner = 0;
  double rectified_baseline = 0;
};

// The loud part: each camera whose approximation errs by more than
// `max_error_px` somewhere over its range.
std::vector<std::string> UndistortionWarnings(const std::vector<CameraUndistortion>& cameras,
                                              double max_error_px);

std::string UndistortionReportText(const std::vector<CameraUndistortion>& cameras,
                                   const std::vector<std::string>& warnings);
std::string UndistortionReportYaml(const std::vector<CameraUndistortion>& cameras,
                                   const std::vector<std::string>& warnings);
// The page: the text, then per camera behind a port an error map per depth
// (colour bar shared by the camera's maps).
HtmlReport UndistortionHtml(const std::vector<CameraUndistortion>& cameras,
                            const std::vector<std::string>& warnings);

}  // namespace portcal
