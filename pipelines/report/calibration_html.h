// The report.html of each kind of calibration: what its pictures show, in
// the order a person checks them, with the text report below.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "colmap_ext/io/sparse_model.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/held_out_evaluation.h"
#include "pipelines/report/html_report.h"

namespace portcal {

// A target calibration (camera or housing) of `views`: coverage, per-view
// RMS, residual vectors and their histogram, the worst views, projection
// uncertainty, the lens's distortion and correlations, the housing to
// scale; with `image_root` (the images' folder) the worst views on their
// images and every view's thumbnail with its corners.
HtmlReport CalibrationHtml(const CalibrationReport& report,
                           const std::vector<CalibrationView>& views, const std::string& title,
                           const std::filesystem::path& image_root = {});

// The projection uncertainty of a target calibration of `views` (report's
// camera, housing, kept views' poses, board warp, held parameters and
// residual sigma): what calibration.yaml carries and the report draws.
ProjectionUncertaintyGrid ProjectionUncertaintyOf(const CalibrationReport& report,
                                                  const std::vector<CalibrationView>& views);

// A stereo calibration: the rig from above, then each camera's coverage
// and per-view RMS.
HtmlReport StereoCalibrationHtml(const StereoCalibrationResult& result,
                                 const std::vector<CalibrationView>& views1,
                                 const std::vector<CalibrationView>& views2,
                                 const std::string& report_text);

// A held-out evaluation: coverage, per-view held-out RMS, residual vectors
// and the residuals' mean per cell.
HtmlReport EvaluationHtml(const HeldOutEvaluation& evaluation,
                          const std::vector<CalibrationView>& views, const HousedCamera& camera,
                          const std::string& report_text);

// A self-calibration (auto_calibrator, refractive_bundle_adjuster) of
// `model`'s first camera: the reconstruction from above, the features'
// coverage, per-image RMS, residual vectors, the housing to scale.
HtmlReport SelfCalibrationHtml(const CalibrationReport& report, const SparseModel& model,
                               const std::string& title);

// A cross-check against mrcal: the projection differences (PNG files the
// stage wrote into the folder, named here), then portcal's calibration of
// the same views as CalibrationHtml shows it.
HtmlReport CrossCheckHtml(const CalibrationReport& portcal,
                          const std::vector<CalibrationView>& views,
                          const std::vector<ReportPicture>& difference_maps,
                          const std::string& report_text);

// The page's form of a verdict.
HtmlVerdict HtmlVerdictOf(const CalibrationVerdict& verdict);

// Writes `html` into `dir` (created). Throws InputError.
void WriteHtml(const HtmlReport& html, const std::filesystem::path& dir);

}  // namespace portcal
