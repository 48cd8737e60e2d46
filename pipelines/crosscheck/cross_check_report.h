// What `portcal cross_check` found, and its files: cross_check.txt for
// people (ending in the PASS / FAIL line), cross_check.yaml for programs.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pipelines/calibration/calibration_verdict.h"
#include "pipelines/crosscheck/projection_diff.h"

namespace portcal {

// One lens parameter in mrcal's parameterisation, COLMAP pixel convention.
struct ParameterComparison {
  std::string name;
  double portcal = 0, portcal_std_dev = 0;  // 0: held by portcal's model; -1: undetermined
  double mrcal = 0, mrcal_std_dev = 0;
  double z = 0;  // (mrcal - portcal) / sqrt(both variances); 0 if both held, NaN if undetermined
};

struct FoldComparison {
  int fold_a = 0, fold_b = 0;
  int views_a = 0, views_b = 0;
  double mean_px = 0, p95_px = 0;
  double predicted_mean_px = 0, predicted_p95_px = 0;
};

struct CrossValidation {
  std::string settings;  // e.g. "as the input calibration (flat board)"
  std::vector<FoldComparison> pairs;
  double worst_ratio = 0;  // max over pairs of p95 / predicted p95
  std::string verdict;
};

struct CrossCheckResult {
  std::string camera_model, mrcal_lensmodel;
  int num_views = 0, num_points = 0;
  double portcal_rms_px = 0, mrcal_rms_px = 0;
  int mrcal_outliers = 0;
  std::vector<std::pair<std::string, int>> mrcal_outliers_per_view;  // views with any
  std::optional<Eigen::Vector2d> portcal_warp, portcal_warp_std_dev;
  Eigen::Vector2d mrcal_warp = Eigen::Vector2d::Zero();
  Eigen::Vector2d mrcal_warp_std_dev = Eigen::Vector2d::Zero();
  std::vector<ParameterComparison> parameters;
  ProjectionDiff diff;  // portcal (A) vs mrcal (B)
  double max_diff_px = 0.5;
  bool pass = false;

  std::vector<std::string> causes;  // likely causes of a disagreement
  // portcal re-run with the board warp (and without mrcal's outliers).
  std::string rerun_description;
  std::optional<ProjectionDiff> rerun_diff;
  std::vector<ParameterComparison> rerun_parameters;

  // With --CrossCheck.folds: the input's settings, then the re-run's.
  std::vector<CrossValidation> cross_validations;

  // What the report opens with: portcal's calibration of the views judged
  // (JudgeCalibration), then this comparison's findings
  // (AddCrossCheckFindings).
  std::optional<CalibrationVerdict> verdict;

  std::string Verdict() const;  // the last line: "PASS ..." / "FAIL ..."
};

// mrcal's agreement (CHECK when it disagrees, naming the likely cause and
// whether the re-run agrees) and each cross-validation's consistency
// (CHECK when NOT consistent), added to `verdict`.
void AddCrossCheckFindings(const CrossCheckResult& result, CalibrationVerdict* verdict);

std::string CrossCheckText(const CrossCheckResult& result);
// Writes cross_check.txt and cross_check.yaml into `dir`, atomically.
std::string WriteCrossCheckReport(const CrossCheckResult& result, const std::filesystem::path& dir);

}  // namespace portcal
