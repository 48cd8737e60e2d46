// `portcal housing_calibrator`: the flat or dome port of a camera whose
// in-air intrinsics are known (--input_calibration), from the target
// observations of its underwater views; writes the reports.
#pragma once

#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/housing_calibration.h"

namespace portcal {

struct HousingCalibratorOptions {
  std::string database_path;
  std::string input_calibration;  // calibration.yaml (portcal or calibmar)
  std::string output_path;
  std::optional<Housing> housing;  // required: the constants and a guess
  int camera_id = -1;
  HousingCalibrationSettings calibration;
  // Writes the housing (portcal_housings) and the intrinsics into the
  // database camera, so that the next stage starts from them.
  bool update_database = false;
  void Check() const;  // throws OptionError naming the option
};

// The stage's summary is the calibration itself.
using HousingCalibratorSummary = HousingCalibrationResult;

HousingCalibratorSummary RunHousingCalibrator(const HousingCalibratorOptions& options, ProgressSink& progress);

}  // namespace portcal
