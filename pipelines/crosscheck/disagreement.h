// Why portcal's and mrcal's calibrations of the same views differ: the
// causes cross_check names (an input that is not portcal's solution of
// these views, mrcal's board warp, outliers, parameterisation,
// regularisation) and portcal re-run as mrcal solved it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/crosscheck/cross_check_report.h"
#include "pipelines/crosscheck/mrcal_calibration.h"
#include "pipelines/crosscheck/projection_diff.h"

namespace portcal {

// A cause when `input` is not portcal's solution of these observations
// (`resolved`): they project more than 0.01 px apart on average.
void NoteResolveDifference(const Camera& input, const Camera& resolved,
                           const ProjectionDiffOptions& diff_options, CrossCheckResult* result);

// mrcal's fit, outliers (per view) and board warp into the result.
void NoteMrcalSolution(const std::vector<CalibrationView>& views,
                       const MrcalCalibrationResult& mrcal, CrossCheckResult* result);

// The differences between the two solvers' problems, strongest evidence
// first, as causes.
void ExplainDisagreement(const CalibrationReport& input, const std::string& lensmodel,
                         const MrcalCalibrationResult& mrcal, bool warp_cause, bool outlier_cause,
                         bool mrcal_regularization, CrossCheckResult* result);

// portcal re-run with what mrcal did differently (board warp; without its
// outlier corners when `outlier_cause`), compared again and its heat map
// written into `dir`; returns the views it used.
std::vector<CalibrationView> RerunAsMrcal(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const MrcalCalibrationResult& mrcal,
                                          bool outlier_cause,
                                          const ProjectionDiffOptions& diff_options,
                                          const std::filesystem::path& dir,
                                          CameraCalibrationSettings* rerun_settings,
                                          CrossCheckResult* result);

}  // namespace portcal
