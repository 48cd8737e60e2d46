// `portcal image_undistorter`: hands a calibration to the tools that take
// only pinholes. From a sparse model (with housings.txt, or a stock one) it
// writes a COLMAP dense workspace as `colmap image_undistorter` does
// (images/, sparse/ with PINHOLE cameras and the same poses, stereo/ and
// the run scripts); from one calibration file, the undistorted images of
// a folder and the pinhole camera. Behind a port the pinhole is an
// approximation chosen for a design depth; the report (undistortion.txt,
// undistortion.yaml, report/report.html with error maps) says how good it
// is over a depth range. Optionally the remap tables (maps/).
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/util/progress.h"
#include "pipelines/undistortion/undistortion_plan.h"
#include "pipelines/undistortion/undistortion_report.h"

namespace portcal {

// The planning options (field of view, distance or depth range, error
// depths, threads) come from UndistortionPlanOptions.
struct ImageUndistorterOptions : UndistortionPlanOptions {
  // A sparse-model folder (cameras, images, points3D; housings.txt), or a
  // calibration file (any ReadCalibrationReport reads; with its housing)
  // for every image of image_path.
  std::string input_path;
  std::string image_path;
  std::string output_path;    // the workspace folder (created)
  double max_error_px = 1.0;  // a worst error above this is a warning
  bool write_maps = false;    // maps/camera_<id>.yaml.gz (OpenCV FileStorage)

  void Check() const;  // throws OptionError naming --Undistort.* or the option
};

struct ImageUndistorterSummary {
  size_t num_images = 0;
  std::vector<CameraUndistortion> cameras;
  std::vector<std::string> warnings;
};

// Throws InputError naming the file, image, camera or option at fault; a
// failed run leaves output_path as it was.
ImageUndistorterSummary RunImageUndistorter(const ImageUndistorterOptions& options,
                                            ProgressSink& progress);

}  // namespace portcal
