// `portcal housing_calibrator`: the flat or dome port of a camera from the
// target observations of its underwater views, the in-air intrinsics given
// (--input_calibration) or, better, solved jointly with the camera's in-air
// views (--in_air_database_path), so that the housing's standard
// deviations include the intrinsics' uncertainty; writes the reports.
#pragma once

#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/housing_calibration.h"

namespace portcal {

inline HousingCalibrationSettings HousingWithBoardWarp() {
  HousingCalibrationSettings settings;
  settings.estimate_board_warp = true;
  return settings;
}

struct HousingCalibratorOptions {
  std::string database_path;
  // calibration.yaml (portcal or calibmar): the intrinsics, fixed unless
  // refined; with in_air_database_path the start of the joint solve, its
  // held parameters held ("" there: calibrated from the in-air views first).
  std::string input_calibration;
  // The same camera's in-air target observations (may be database_path,
  // another camera of it): the intrinsics are refined jointly.
  std::string in_air_database_path;
  int in_air_camera_id = -1;
  std::string output_path;
  // The underwater images' folder, optional: the report draws the worst
  // views and every view's thumbnail on them.
  std::string image_path;
  std::optional<Housing> housing;  // required: the constants and a guess
  int camera_id = -1;
  // The board's sag fitted, as camera_calibrator does: the underwater
  // views' own, and in a joint solve the in-air views' own too, unless
  // share_board_warp (the same board in one session: a board's sag changes
  // between sessions, 10 sigma in x on the real dome set).
  HousingCalibrationSettings calibration = HousingWithBoardWarp();
  bool share_board_warp = false;
  // Writes the housing (portcal_housings) and the intrinsics into the
  // database camera, so that the next stage starts from them.
  bool update_database = false;
  void Check() const;  // throws OptionError naming the option
};

// The stage's summary is the calibration itself.
using HousingCalibratorSummary = HousingCalibrationResult;

HousingCalibratorSummary RunHousingCalibrator(const HousingCalibratorOptions& options,
                                              ProgressSink& progress);

}  // namespace portcal
