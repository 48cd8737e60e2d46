// A portcal board calibration as mrcal's optimization_inputs, so that
// mrcal's own tools (mrcal-show-projection-uncertainty, mrcal-show-
// residuals-board-observation, mrcal.optimizer_callback, ...) evaluate
// portcal's solution: the kept views' corners and poses, the lens, the
// board warp, and what was estimated.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/io/mrcal_model.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

// The solve of `result` (from CalibrateCamera(views, ..., settings)) as
// mrcal sees it; the dropped views are left out. Empty, with `why_not`
// set, where mrcal cannot express it: a lens model mrcal lacks, a target
// that is not one square grid, parameters held that mrcal would free.
std::optional<MrcalBoardSolve> MrcalBoardSolveOfCalibration(
    const std::vector<CalibrationView>& views, const CameraCalibrationResult& result,
    const CameraCalibrationSettings& settings, std::string* why_not);

// Writes `dir`/camera.cameramodel with the optimization_inputs where mrcal
// can express the solve, without them (and a log line saying why) where it
// cannot, and nothing for a lens model mrcal lacks. Returns the file
// written, or an empty path.
std::filesystem::path WriteCalibrationCameraModel(const std::vector<CalibrationView>& views,
                                                  const CameraCalibrationResult& result,
                                                  const CameraCalibrationSettings& settings,
                                                  const std::filesystem::path& dir);

}  // namespace portcal
