// The verdict a report opens with: OK, CHECK or FAIL, and each rule's
// finding, so that a person who reads one line knows whether to keep the
// calibration and, if not, what to do. The rules and the figures behind
// their thresholds: docs/calibration.md, "The verdict".
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "colmap_ext/io/sparse_model.h"

namespace portcal {

struct CalibrationReport;
struct CalibrationView;
struct FoldEvaluation;
struct StereoCalibrationResult;
struct HeldOutEvaluation;

enum class VerdictStatus { kOk = 0, kCheck = 1, kFail = 2 };
std::string VerdictStatusName(VerdictStatus status);  // "OK", "CHECK", "FAIL"

struct VerdictLine {
  VerdictStatus status = VerdictStatus::kOk;
  std::string rule;  // e.g. "residuals", "coverage"
  std::string text;  // the finding, with its figures and, when not OK, what to do
};

struct CalibrationVerdict {
  VerdictStatus status = VerdictStatus::kOk;  // the worst line's
  std::vector<VerdictLine> lines;             // worst first, then in the rules' order

  void Add(VerdictStatus line_status, const std::string& rule, const std::string& text);
  // "CHECK (coverage: ...; views: ...)": the status and the lines not OK.
  std::string Summary() const;
};

struct VerdictRules {
  // The RMS reprojection error (px) above which the corners or the model
  // are suspect, and above which the calibration is not usable.
  double rms_check_px = 1.0;
  double rms_fail_px = 3.0;
  // Fewer kept views than this: CHECK (too few to separate the lens from
  // the poses reliably, and to tell a bad view from a good one).
  int min_views = 10;
  // The fraction of the coverage grid's cells (coverage.png: 16 across)
  // that must hold a corner, and how many of the image's corners (of a
  // 3 x 3 split) may hold none.
  double min_covered_fraction = 0.5;
  int max_empty_image_corners = 1;
  // mrcal's projection uncertainty, the worst cell (px): at the working
  // distance (CHECK, FAIL) and at infinity (CHECK).
  double uncertainty_check_px = 1.0;
  double uncertainty_fail_px = 3.0;
  double uncertainty_at_infinity_check_px = 2.0;
  // Held out: views fitted this much worse than the calibration's own
  // (or its folds' training) RMS; a residual pattern this many times the
  // cells' own scatter (held_out_evaluation.h).
  double held_out_ratio_check = 1.25;
  double pattern_ratio_check = 3.0;
  void Check() const;  // throws OptionError
};

// Coverage counts over the image: cols x rows cells (cols 16, rows in
// proportion), as coverage.png draws them.
Eigen::MatrixXi CoverageCounts(int width, int height, const std::vector<Eigen::Vector2d>& pixels);

// The image's corners ("top-left", "top-right", "bottom-left",
// "bottom-right") of a 3 x 3 split where no pixel falls: the verdict's
// coverage rule and the live goal's limits name them.
std::vector<std::string> EmptyImageCorners(int width, int height,
                                           const std::vector<Eigen::Vector2d>& pixels);

// "a", "a and b", "a, b and c".
std::string JoinedWords(const std::vector<std::string>& words);

// Judges a target or self-calibration: its warnings (undetermined
// parameters: FAIL; others: CHECK), RMS, outlier views, number of views,
// coverage of `pixels` (the observations, COLMAP pixels), the projection
// uncertainty when computed, and a housing whose lens was taken as exact.
CalibrationVerdict JudgeCalibration(const CalibrationReport& report,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    const VerdictRules& rules = VerdictRules());
// The same, the pixels those of a target calibration's `views`.
CalibrationVerdict JudgeCalibration(const CalibrationReport& report,
                                    const std::vector<CalibrationView>& views,
                                    const VerdictRules& rules = VerdictRules());

// The same, the pixels those of camera `camera_id`'s observations of the
// model's points (a self-calibration's).
CalibrationVerdict JudgeCalibration(const CalibrationReport& report, const SparseModel& model,
                                    camera_t camera_id, const VerdictRules& rules = VerdictRules());

// Judges a stereo calibration of the frames' views: RMS, frames and their
// outliers, each camera's coverage, and whether the rig is determined.
CalibrationVerdict JudgeStereo(const StereoCalibrationResult& result,
                               const std::vector<CalibrationView>& views1,
                               const std::vector<CalibrationView>& views2,
                               const VerdictRules& rules = VerdictRules());

// Judges a held-out evaluation of `input` (its RMS, when it has one, is
// the fit's own): the held-out RMS against the thresholds and against the
// fit's, the residual pattern, the views not evaluated, and with `folds`
// the cross-validation's held-out against training RMS.
CalibrationVerdict JudgeHeldOut(const HeldOutEvaluation& evaluation, const CalibrationReport& input,
                                const std::vector<FoldEvaluation>& folds,
                                double cross_validation_rms_px,
                                const VerdictRules& rules = VerdictRules());

// calibration.txt's verdict block and calibration.yaml's `verdict:` key
// (status, reasons: the lines not OK, findings: every line).
std::string VerdictText(const CalibrationVerdict& verdict);
std::string VerdictYaml(const CalibrationVerdict& verdict);

}  // namespace portcal
