// `portcal project_points`: 3-D points (camera frame, metres) to pixels
// through a camera and an optional housing, or pixels to rays with
// `unproject`.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"

namespace portcal {

struct ProjectPointsOptions {
  // The camera, from one of: a sparse model (input_path + camera_id, with
  // its housings.txt; camera_id -1: the model's only camera), a calibration
  // file (input_calibration: any format ReadCalibrationReport reads, with its
  // housing), or the Camera.* options. Housing.* adds a housing to the
  // Camera.* options or replaces the calibration file's.
  std::string input_path;
  int camera_id = -1;
  std::string input_calibration;
  std::string camera_model;   // COLMAP name, e.g. RADIAL
  std::string camera_params;  // comma/space separated, COLMAP order
  int width = 0;              // pixels, > 0
  int height = 0;
  std::optional<Housing> housing;  // none: in air

  std::string points_path;  // input text file: "X Y Z" or "x y" per line
  bool unproject = false;   // pixels -> rays instead of points -> pixels

  void Check() const;  // throws OptionError naming the option
};

struct ProjectPointsSummary {
  // One per input line (comments and blank lines skipped): "x y" for a
  // projected point, "ox oy oz dx dy dz" for an unprojected pixel (origin on
  // the port's outer surface, unit direction), or "invalid <reason>" where
  // there is no answer.
  std::vector<std::string> lines;
  int num_invalid = 0;
};

// Throws InputError naming the file and line for malformed input.
ProjectPointsSummary RunProjectPoints(const ProjectPointsOptions& options, ProgressSink& progress);

}  // namespace portcal
