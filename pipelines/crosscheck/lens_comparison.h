// portcal's and mrcal's lenses side by side: their parameters in mrcal's
// order with z-scores, each as a CalibratedLens for projection differences,
// whether mrcal's board warp is significant, and K-fold cross-validation of
// portcal's calibration (folds differenced against what their covariances
// predict).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/crosscheck/cross_check_report.h"
#include "pipelines/crosscheck/mrcal_calibration.h"
#include "pipelines/crosscheck/projection_diff.h"

namespace portcal {

// Both calibrations in mrcal's parameterisation of the lens.
std::vector<ParameterComparison> CompareParameters(const Camera& portcal,
                                                   const std::vector<double>& portcal_std_dev,
                                                   const MrcalCalibrationResult& mrcal);

CalibratedLens LensOf(const CameraCalibrationResult& result);
CalibratedLens LensOf(const MrcalCalibrationResult& result);
// The views' cam_from_target, in order.
std::vector<Rigid3d> Poses(const CameraCalibrationResult& result);
// A warp term of mrcal's beyond 3 of its standard deviations.
bool WarpSignificant(const MrcalCalibrationResult& mrcal);

// Cross-validation: disjoint interleaved subsets (view i in fold i mod
// `folds`, so each fold spans the whole capture), each calibrated alone,
// every pair differenced (on a grid `gridn_width` wide) and set against the
// difference their covariances predict; the first pair's heat map written
// to `heat_map`. InputError (naming --CrossCheck.folds) when a fold gets
// fewer than 3 views.
CrossValidation CrossValidate(const std::vector<CalibrationView>& views, const Camera& initial,
                              const CameraCalibrationSettings& settings, int folds, int gridn_width,
                              const std::string& description,
                              const std::filesystem::path& heat_map);

}  // namespace portcal
