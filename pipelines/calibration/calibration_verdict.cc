#include "pipelines/calibration/calibration_verdict.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/held_out_evaluation.h"
#include "pipelines/calibration/stereo_calibration.h"

namespace portcal {

std::string VerdictStatusName(VerdictStatus status) {
  return status == VerdictStatus::kOk ? "OK" : status == VerdictStatus::kCheck ? "CHECK" : "FAIL";
}

void CalibrationVerdict::Add(VerdictStatus line_status, const std::string& rule,
                             const std::string& text) {
  lines.push_back({line_status, rule, text});
  // Worst first, the rules' order kept among equals.
  std::stable_sort(lines.begin(), lines.end(),
                   [](const VerdictLine& a, const VerdictLine& b) { return a.status > b.status; });
  status = std::max(status, line_status);
}

std::string CalibrationVerdict::Summary() const {
  std::string text = VerdictStatusName(status);
  std::string reasons;
  for (const VerdictLine& line : lines) {
    if (line.status != VerdictStatus::kOk)
      reasons += (reasons.empty() ? "" : "; ") + line.rule + ": " + line.text;
  }
  return reasons.empty() ? text : text + " (" + reasons + ")";
}

void VerdictRules::Check() const {
  if (!(rms_check_px > 0 && rms_fail_px >= rms_check_px)) {
    throw OptionError("verdict rms_check_px / rms_fail_px", FormatShortest(rms_check_px),
                      "0 < check <= fail");
  }
  if (min_views < 1) throw OptionError("verdict min_views", min_views, ">= 1");
  if (!(min_covered_fraction >= 0 && min_covered_fraction <= 1)) {
    throw OptionError("verdict min_covered_fraction", FormatShortest(min_covered_fraction),
                      "in [0, 1]");
  }
  if (!(held_out_ratio_check > 1 && pattern_ratio_check > 1)) {
    throw OptionError("verdict held-out ratios", FormatShortest(held_out_ratio_check), "> 1");
  }
  if (!(uncertainty_check_px > 0 && uncertainty_fail_px >= uncertainty_check_px &&
        uncertainty_at_infinity_check_px > 0)) {
    throw OptionError("verdict uncertainty thresholds", FormatShortest(uncertainty_check_px),
                      "0 < check <= fail");
  }
}

Eigen::MatrixXi CoverageCounts(int width, int height, const std::vector<Eigen::Vector2d>& pixels) {
  // Cells of ~1/16 of the image width: fine enough to show a bare corner,
  // coarse enough that one board's points fill several.
  const int cols = 16,
            rows = std::max(2, static_cast<int>(std::lround(16.0 * height / std::max(1, width))));
  Eigen::MatrixXi counts = Eigen::MatrixXi::Zero(rows, cols);
  for (const Eigen::Vector2d& p : pixels) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    const int c = std::clamp(static_cast<int>(p.x() / width * cols), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(p.y() / height * rows), 0, rows - 1);
    counts(r, c) += 1;
  }
  return counts;
}

std::vector<std::string> EmptyImageCorners(int width, int height,
                                           const std::vector<Eigen::Vector2d>& pixels) {
  bool seen[2][2] = {{false, false}, {false, false}};
  for (const Eigen::Vector2d& p : pixels) {
    const int col = static_cast<int>(3 * p.x() / width), row = static_cast<int>(3 * p.y() / height);
    if ((col == 0 || col == 2) && (row == 0 || row == 2)) seen[row / 2][col / 2] = true;
  }
  std::vector<std::string> empty;
  const char* names[2][2] = {{"top-left", "top-right"}, {"bottom-left", "bottom-right"}};
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) {
      if (!seen[r][c]) empty.emplace_back(names[r][c]);
    }
  }
  return empty;
}

std::string JoinedWords(const std::vector<std::string>& words) {
  std::string text;
  for (size_t i = 0; i < words.size(); ++i)
    text += (i == 0 ? "" : i + 1 == words.size() ? " and " : ", ") + words[i];
  return text;
}

namespace {

std::vector<Eigen::Vector2d> PixelsOf(const std::vector<CalibrationView>& views) {
  std::vector<Eigen::Vector2d> pixels;
  for (const CalibrationView& view : views)
    pixels.insert(pixels.end(), view.pixels.begin(), view.pixels.end());
  return pixels;
}

void JudgeRms(double rms, int num_points, const VerdictRules& rules, CalibrationVerdict* verdict) {
  std::ostringstream text;
  text << "RMS " << FormatFixed(rms, 3) << " px over " << num_points << " points";
  if (!std::isfinite(rms)) {
    verdict->Add(VerdictStatus::kFail, "residuals", "the RMS is not a number: the solve failed");
  } else if (rms > rules.rms_fail_px) {
    text << " > " << FormatShortest(rules.rms_fail_px)
         << " px: the corners or the camera model are wrong "
         << "(another model, --Target size, or the views' per-view RMS below)";
    verdict->Add(VerdictStatus::kFail, "residuals", text.str());
  } else if (rms > rules.rms_check_px) {
    text << " > " << FormatShortest(rules.rms_check_px)
         << " px (sharp corners reach 0.1-0.5 px): look for blur, "
         << "a misdetected view or a model that does not fit (residuals.png)";
    verdict->Add(VerdictStatus::kCheck, "residuals", text.str());
  } else {
    verdict->Add(VerdictStatus::kOk, "residuals",
                 text.str() + " (<= " + FormatShortest(rules.rms_check_px) + " px)");
  }
}

void JudgeViews(const std::vector<CalibratedView>& views, const VerdictRules& rules,
                CalibrationVerdict* verdict) {
  int kept = 0;
  std::vector<std::string> outliers;
  for (const CalibratedView& view : views) {
    if (view.dropped) continue;
    ++kept;
    if (view.outlier) outliers.push_back(view.image_name);
  }
  if (!outliers.empty()) {
    std::vector<std::string> named(outliers.begin(),
                                   outliers.begin() + std::min<size_t>(outliers.size(), 3));
    if (outliers.size() > 3) named.push_back(std::to_string(outliers.size() - 3) + " more");
    verdict->Add(VerdictStatus::kCheck, "views",
                 std::to_string(outliers.size()) +
                     " outlier view(s) kept in the solve: " + JoinedWords(named) +
                     " (look at them; --Calibration.drop_outlier_views 1 leaves them out)");
  }
  if (kept < rules.min_views) {
    verdict->Add(VerdictStatus::kCheck, "views",
                 std::to_string(kept) + " views < " + std::to_string(rules.min_views) +
                     ": too few to tell a bad view from a good one; add views, tilted and nearer "
                     "the image corners");
  } else if (outliers.empty()) {
    verdict->Add(VerdictStatus::kOk, "views", std::to_string(kept) + " views, no outlier");
  }
}

void JudgeCoverage(const Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                   const VerdictRules& rules, const std::string& rule,
                   CalibrationVerdict* verdict) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  const Eigen::MatrixXi counts = CoverageCounts(width, height, pixels);
  const int cells = static_cast<int>(counts.size()),
            empty = static_cast<int>((counts.array() == 0).count());
  const double covered = cells > 0 ? 1.0 - static_cast<double>(empty) / cells : 0;
  const std::vector<std::string> empty_corners = EmptyImageCorners(width, height, pixels);
  std::ostringstream text;
  text << empty << " of " << cells << " cells empty (" << std::lround(100 * covered)
       << " % covered)";
  if (!empty_corners.empty()) {
    text << "; the image's " << JoinedWords(empty_corners) << " corner"
         << (empty_corners.size() > 1 ? "s hold" : " holds") << " no point (of a 3 x 3 split)";
  }
  // One bare corner is common in good hand-held sets (the real in-air
  // set's bottom-left): the uncertainty rule judges what it costs there.
  if (covered < rules.min_covered_fraction ||
      static_cast<int>(empty_corners.size()) > rules.max_empty_image_corners) {
    text << ": the lens is extrapolated over the dark cells of coverage.png; add views that fill "
            "them";
    verdict->Add(VerdictStatus::kCheck, rule, text.str());
  } else {
    verdict->Add(VerdictStatus::kOk, rule, text.str());
  }
}

void JudgeUncertainty(const ProjectionUncertaintyGrid& grid, const VerdictRules& rules,
                      CalibrationVerdict* verdict) {
  if (!grid.determined) {
    verdict->Add(VerdictStatus::kFail, "uncertainty",
                 "the views do not fix the " + grid.of + " (no finite projection uncertainty)");
    return;
  }
  const double near = grid.Max(false), far = grid.Max(true);
  std::ostringstream text;
  text << "projection uncertainty of the " << grid.of << " (mrcal's, worst cell) "
       << FormatFixed(near, 3) << " px at " << FormatFixed(grid.working_distance_m, 2) << " m, "
       << FormatFixed(far, 3) << " px at infinity";
  if (near > rules.uncertainty_fail_px) {
    text << " > " << FormatShortest(rules.uncertainty_fail_px)
         << " px: add views, nearer the image corners";
    verdict->Add(VerdictStatus::kFail, "uncertainty", text.str());
  } else if (near > rules.uncertainty_check_px) {
    text << " > " << FormatShortest(rules.uncertainty_check_px)
         << " px at the working distance (uncertainty.png "
         << "shows where): add views there";
    verdict->Add(VerdictStatus::kCheck, "uncertainty", text.str());
  } else if (far > rules.uncertainty_at_infinity_check_px) {
    text << " > " << FormatShortest(rules.uncertainty_at_infinity_check_px)
         << " px at infinity: far points project loosely; add views of the target farther away";
    verdict->Add(VerdictStatus::kCheck, "uncertainty", text.str());
  } else {
    verdict->Add(VerdictStatus::kOk, "uncertainty", text.str());
  }
}

}  // namespace

CalibrationVerdict JudgeCalibration(const CalibrationReport& report,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    const VerdictRules& rules) {
  rules.Check();
  CalibrationVerdict verdict;
  for (const std::string& warning : report.warnings) {
    // Undetermined parameters' values mean nothing: not usable as is.
    const bool undetermined = warning.rfind("the views do not determine", 0) == 0;
    verdict.Add(undetermined ? VerdictStatus::kFail : VerdictStatus::kCheck, "warning", warning);
  }
  JudgeRms(report.overall_rms_px, report.num_points, rules, &verdict);
  JudgeViews(report.views, rules, &verdict);
  JudgeCoverage(report.camera, pixels, rules, "coverage", &verdict);
  if (report.projection_uncertainty)
    JudgeUncertainty(*report.projection_uncertainty, rules, &verdict);
  for (const std::string& note : report.notes) {
    if (note.find("taken as exact") != std::string::npos) {
      verdict.Add(VerdictStatus::kCheck, "housing",
                  "the in-air intrinsics were taken as exact: the housing's standard deviations "
                  "understate its "
                  "error (give the in-air views, or a calibration.yaml with its covariance)");
    }
  }
  return verdict;
}

CalibrationVerdict JudgeCalibration(const CalibrationReport& report,
                                    const std::vector<CalibrationView>& views,
                                    const VerdictRules& rules) {
  return JudgeCalibration(report, PixelsOf(views), rules);
}

CalibrationVerdict JudgeCalibration(const CalibrationReport& report, const SparseModel& model,
                                    camera_t camera_id, const VerdictRules& rules) {
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& [id, image] : model.images) {
    if (image.camera_id != camera_id) continue;
    for (const Point2D& point : image.points2D) {
      if (point.point3D_id != kInvalidPoint3DId && model.points3D.count(point.point3D_id))
        pixels.push_back(point.xy);
    }
  }
  return JudgeCalibration(report, pixels, rules);
}

CalibrationVerdict JudgeStereo(const StereoCalibrationResult& result,
                               const std::vector<CalibrationView>& views1,
                               const std::vector<CalibrationView>& views2,
                               const VerdictRules& rules) {
  rules.Check();
  CalibrationVerdict verdict;
  JudgeRms(result.overall_rms_px, result.num_points, rules, &verdict);
  // A frame is an outlier where either camera's view is.
  std::vector<CalibratedView> frames = result.views1;
  for (size_t f = 0; f < frames.size() && f < result.views2.size(); ++f) {
    if (result.views2[f].outlier) {
      frames[f].outlier = true;
      frames[f].image_name += " / " + result.views2[f].image_name;
    }
  }
  JudgeViews(frames, rules, &verdict);
  JudgeCoverage(result.camera1, PixelsOf(views1), rules, "coverage, camera 1", &verdict);
  JudgeCoverage(result.camera2, PixelsOf(views2), rules, "coverage, camera 2", &verdict);
  const double baseline = result.cam2_from_cam1.translation.norm();
  const double baseline_sigma = result.translation_std_dev.norm();
  std::ostringstream text;
  text << "baseline " << FormatFixed(1000 * baseline, 2) << " +- "
       << FormatFixed(1000 * baseline_sigma, 2) << " mm";
  if (!std::isfinite(baseline_sigma) || (result.translation_std_dev.array() < 0).any()) {
    verdict.Add(VerdictStatus::kFail, "rig", text.str() + ": the frames do not determine the rig");
  } else {
    verdict.Add(VerdictStatus::kOk, "rig", text.str());
  }
  return verdict;
}

CalibrationVerdict JudgeHeldOut(const HeldOutEvaluation& evaluation, const CalibrationReport& input,
                                const std::vector<FoldEvaluation>& folds,
                                double cross_validation_rms_px, const VerdictRules& rules) {
  rules.Check();
  CalibrationVerdict verdict;
  JudgeRms(evaluation.rms_px, evaluation.num_points, rules, &verdict);
  if (input.overall_rms_px > 0 &&
      evaluation.rms_px > rules.held_out_ratio_check * input.overall_rms_px) {
    verdict.Add(VerdictStatus::kCheck, "held out",
                "these views' RMS " + FormatFixed(evaluation.rms_px, 3) + " px is " +
                    FormatFixed(evaluation.rms_px / input.overall_rms_px, 2) +
                    "x the calibration's own (" + FormatFixed(input.overall_rms_px, 3) +
                    " px): it does not carry to them (another focus, housing or camera?)");
  }
  std::ostringstream pattern;
  pattern << "residual pattern " << FormatFixed(evaluation.systematic_px, 3)
          << " px, the cells' own scatter " << FormatFixed(evaluation.noise_floor_px, 3) << " px";
  if (evaluation.noise_floor_px > 0 &&
      evaluation.systematic_px > rules.pattern_ratio_check * evaluation.noise_floor_px) {
    pattern << " (> " << FormatShortest(rules.pattern_ratio_check)
            << "x): the model misses something over part of the image (pattern.png shows where)";
    verdict.Add(VerdictStatus::kCheck, "pattern", pattern.str());
  } else {
    verdict.Add(VerdictStatus::kOk, "pattern", pattern.str());
  }
  std::vector<std::string> skipped;
  for (const ViewEvaluation& view : evaluation.views) {
    if (!view.evaluated) skipped.push_back(view.image_name + " (" + view.why + ")");
  }
  if (!skipped.empty()) {
    std::vector<std::string> named(skipped.begin(),
                                   skipped.begin() + std::min<size_t>(skipped.size(), 3));
    if (skipped.size() > 3) named.push_back(std::to_string(skipped.size() - 3) + " more");
    verdict.Add(VerdictStatus::kCheck, "views",
                std::to_string(skipped.size()) + " view(s) not evaluated: " + JoinedWords(named));
  }
  if (!folds.empty()) {
    double train = 0;
    for (const FoldEvaluation& fold : folds) train += fold.train_rms_px / folds.size();
    std::ostringstream text;
    text << folds.size() << "-fold cross-validation: held-out RMS "
         << FormatFixed(cross_validation_rms_px, 3) << " px, training " << FormatFixed(train, 3)
         << " px";
    if (train > 0 && cross_validation_rms_px > rules.held_out_ratio_check * train) {
      text << " (> " << FormatShortest(rules.held_out_ratio_check)
           << "x): the model fits its own views better than new ones (too many parameters for the "
              "views?)";
      verdict.Add(VerdictStatus::kCheck, "cross-validation", text.str());
    } else {
      verdict.Add(VerdictStatus::kOk, "cross-validation", text.str());
    }
  }
  return verdict;
}

std::string VerdictText(const CalibrationVerdict& verdict) {
  std::ostringstream out;
  out << "Verdict: " << VerdictStatusName(verdict.status) << "\n";
  for (const VerdictLine& line : verdict.lines) {
    out << "  " << VerdictStatusName(line.status)
        << std::string(6 - VerdictStatusName(line.status).size(), ' ') << line.rule << ": "
        << line.text << "\n";
  }
  return out.str();
}

std::string VerdictYaml(const CalibrationVerdict& verdict) {
  const auto quoted = [](const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
  };
  std::ostringstream out;
  out << "verdict:\n  status: " << VerdictStatusName(verdict.status) << "\n  reasons:";
  int reasons = 0;
  for (const VerdictLine& line : verdict.lines) {
    if (line.status == VerdictStatus::kOk) continue;
    out << "\n  - " << quoted(line.rule + ": " + line.text);
    ++reasons;
  }
  out << (reasons == 0 ? " []\n" : "\n") << "  findings:\n";
  for (const VerdictLine& line : verdict.lines) {
    out << "  - {status: " << VerdictStatusName(line.status) << ", rule: " << quoted(line.rule)
        << ", text: " << quoted(line.text) << "}\n";
  }
  return out.str();
}

}  // namespace portcal
