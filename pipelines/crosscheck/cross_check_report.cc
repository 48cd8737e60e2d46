#include "pipelines/crosscheck/cross_check_report.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {
namespace {

// A YAML single-quoted scalar.
std::string Quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string DiffLine(const ProjectionDiff& diff) {
  return "mean " + FormatFixed(diff.mean_px, 3) + " px, p95 " + FormatFixed(diff.p95_px, 3) +
         " px, max " + FormatFixed(diff.max_px, 3) + " px; worst: " + diff.worst_region +
         " (mean " + FormatFixed(diff.worst_region_mean_px, 3) + " px)";
}

void ParameterTable(std::ostream& out, const std::vector<ParameterComparison>& parameters) {
  out << "  parameter          portcal      +-std dev            mrcal      +-std dev      "
         "difference       z\n";
  for (const ParameterComparison& p : parameters) {
    const std::string portcal_sd = p.portcal_std_dev == 0  ? std::string("(held)")
                                   : p.portcal_std_dev < 0 ? std::string("(undetermined)")
                                                           : FormatFixed(p.portcal_std_dev, 6);
    out << "  " << std::left << std::setw(8) << p.name << std::right << " " << std::setw(16)
        << FormatFixed(p.portcal, 6) << " " << std::setw(14) << portcal_sd << " " << std::setw(16)
        << FormatFixed(p.mrcal, 6) << " " << std::setw(14) << FormatFixed(p.mrcal_std_dev, 6) << " "
        << std::setw(15) << FormatFixed(p.mrcal - p.portcal, 6) << " " << std::setw(7)
        << (std::isfinite(p.z) ? FormatFixed(p.z, 1) : std::string("-")) << "\n";
  }
}

std::string YamlParameters(const std::vector<ParameterComparison>& parameters,
                           const std::string& indent) {
  std::ostringstream out;
  out << std::setprecision(12);
  for (const ParameterComparison& p : parameters) {
    out << indent << "- {name: " << p.name << ", portcal: " << p.portcal << ", portcal_std_dev: "
        << (p.portcal_std_dev < 0 ? std::string("null") : FormatSignificant(p.portcal_std_dev, 12))
        << ", mrcal: " << p.mrcal << ", mrcal_std_dev: " << p.mrcal_std_dev
        << ", z: " << (std::isfinite(p.z) ? FormatSignificant(p.z, 12) : std::string("null"))
        << "}\n";
  }
  return out.str();
}

std::string YamlDiff(const ProjectionDiff& d, const std::string& indent) {
  std::ostringstream out;
  out << std::setprecision(6) << indent << "mean_px: " << d.mean_px << "\n"
      << indent << "p95_px: " << d.p95_px << "\n"
      << indent << "max_px: " << d.max_px << "\n"
      << indent << "worst_region: " << Quoted(d.worst_region) << "\n"
      << indent << "worst_region_mean_px: " << d.worst_region_mean_px << "\n";
  return out.str();
}

}  // namespace

std::string CrossCheckResult::Verdict() const {
  std::string line = std::string(pass ? "PASS" : "FAIL") +
                     ": portcal vs mrcal projection diff p95 " + FormatFixed(diff.p95_px, 3) +
                     " px " + (pass ? "<=" : ">") + " " + FormatFixed(max_diff_px, 3) +
                     " px; worst region: " + diff.worst_region + " (mean " +
                     FormatFixed(diff.worst_region_mean_px, 3) + " px)";
  if (!pass && !causes.empty()) line += "; likely cause: " + causes.front();
  if (!pass && rerun_diff) {
    line += "; " + rerun_description + ": p95 " + FormatFixed(rerun_diff->p95_px, 3) + " px (" +
            (rerun_diff->p95_px <= max_diff_px ? "agree" : "still disagree") + ")";
  }
  return line;
}

void AddCrossCheckFindings(const CrossCheckResult& r, CalibrationVerdict* verdict) {
  const std::string diff = "portcal vs mrcal p95 " + FormatFixed(r.diff.p95_px, 3) + " px";
  if (r.pass) {
    verdict->Add(VerdictStatus::kOk, "mrcal",
                 diff + " <= " + FormatFixed(r.max_diff_px, 3) + " px: they agree");
  } else {
    std::string text = diff + " > " + FormatFixed(r.max_diff_px, 3) + " px: they disagree";
    if (!r.causes.empty()) text += "; likely cause: " + r.causes.front();
    if (r.rerun_diff) {
      text += r.rerun_diff->p95_px <= r.max_diff_px
                  ? "; " + r.rerun_description + " agrees (p95 " +
                        FormatFixed(r.rerun_diff->p95_px, 3) + " px): calibrate so"
                  : "; " + r.rerun_description + " still disagrees";
    }
    verdict->Add(VerdictStatus::kCheck, "mrcal", text);
  }
  for (const CrossValidation& cv : r.cross_validations) {
    // consistent / NOT consistent: CrossValidate's threshold (2x the
    // predicted spread).
    const bool consistent = cv.verdict.rfind("NOT", 0) != 0;
    verdict->Add(consistent ? VerdictStatus::kOk : VerdictStatus::kCheck, "folds",
                 cv.settings + ": " + cv.verdict);
  }
}

std::string CrossCheckText(const CrossCheckResult& r) {
  std::ostringstream out;
  out << "portcal cross_check\n===================\n\n";
  if (r.verdict) out << VerdictText(*r.verdict) << "\n";
  out << "Camera model " << r.camera_model << " (mrcal: " << r.mrcal_lensmodel << "), "
      << r.num_views << " views, " << r.num_points << " corners\n"
      << "RMS reprojection error: portcal " << FormatFixed(r.portcal_rms_px, 4) << " px, mrcal "
      << FormatFixed(r.mrcal_rms_px, 4) << " px (inliers)\n"
      << "mrcal rejected " << r.mrcal_outliers << " corners as outliers";
  if (!r.mrcal_outliers_per_view.empty()) {
    out << " (";
    for (size_t i = 0; i < r.mrcal_outliers_per_view.size(); ++i) {
      out << (i ? ", " : "") << r.mrcal_outliers_per_view[i].first << ": "
          << r.mrcal_outliers_per_view[i].second;
    }
    out << ")";
  }
  out << "\nBoard warp (parabolic sag, mm): mrcal x " << FormatFixed(r.mrcal_warp.x() * 1e3, 3)
      << " +- " << FormatFixed(r.mrcal_warp_std_dev.x() * 1e3, 3) << ", y "
      << FormatFixed(r.mrcal_warp.y() * 1e3, 3) << " +- "
      << FormatFixed(r.mrcal_warp_std_dev.y() * 1e3, 3);
  if (r.portcal_warp) {
    out << "; portcal x " << FormatFixed(r.portcal_warp->x() * 1e3, 3) << " +- "
        << FormatFixed(r.portcal_warp_std_dev->x() * 1e3, 3) << ", y "
        << FormatFixed(r.portcal_warp->y() * 1e3, 3) << " +- "
        << FormatFixed(r.portcal_warp_std_dev->y() * 1e3, 3);
  } else {
    out << "; portcal: flat board";
  }
  out << "\n\nParameters (COLMAP pixel convention; z = difference / combined std dev)\n";
  ParameterTable(out, r.parameters);
  out << "\nProjection difference (mrcal's definition: rays at infinity, best-fit rotation, "
      << r.diff.grid_width << "x" << r.diff.grid_height
      << " grid; heat map projection_diff.png)\n  " << DiffLine(r.diff) << "\n";
  if (!r.causes.empty()) {
    out << "\nLikely causes of the disagreement\n";
    for (const std::string& cause : r.causes) out << "  - " << cause << "\n";
  }
  if (r.rerun_diff) {
    out << "\nRe-run: " << r.rerun_description << " (heat map projection_diff_rerun.png)\n  "
        << DiffLine(*r.rerun_diff) << "\n  "
        << (r.rerun_diff->p95_px <= r.max_diff_px ? "the two now agree" : "the two still disagree")
        << " (threshold p95 " << FormatFixed(r.max_diff_px, 3) << " px)\n";
    ParameterTable(out, r.rerun_parameters);
  }
  for (const CrossValidation& cv : r.cross_validations) {
    out << "\nCross-validation, " << cv.settings << " (" << cv.pairs.size()
        << " pair(s) of disjoint, interleaved view subsets, each calibrated alone; predicted = "
        << "what their uncertainty allows)\n"
        << "  folds   views      mean    p95    predicted mean    p95\n";
    for (const FoldComparison& f : cv.pairs) {
      out << "  " << f.fold_a << " vs " << f.fold_b << "  " << std::setw(3) << f.views_a << "/"
          << std::left << std::setw(3) << f.views_b << std::right << std::setw(9)
          << FormatFixed(f.mean_px, 3) << std::setw(7) << FormatFixed(f.p95_px, 3) << std::setw(17)
          << FormatFixed(f.predicted_mean_px, 3) << std::setw(7)
          << FormatFixed(f.predicted_p95_px, 3) << "\n";
    }
    out << "  " << cv.verdict << "\n";
  }
  out << "\n" << r.Verdict() << "\n";
  return out.str();
}

std::string WriteCrossCheckReport(const CrossCheckResult& r, const std::filesystem::path& dir) {
  std::ostringstream yaml;
  yaml << std::setprecision(10) << "# portcal cross_check\n"
       << "camera_model: " << r.camera_model << "\nmrcal_lensmodel: " << r.mrcal_lensmodel
       << "\nnum_views: " << r.num_views << "\nnum_points: " << r.num_points
       << "\nportcal_rms_px: " << r.portcal_rms_px << "\nmrcal_rms_px: " << r.mrcal_rms_px
       << "\nmrcal_outliers: " << r.mrcal_outliers << "\nmrcal_board_warp: [" << r.mrcal_warp.x()
       << ", " << r.mrcal_warp.y() << "]\nmrcal_board_warp_std_dev: [" << r.mrcal_warp_std_dev.x()
       << ", " << r.mrcal_warp_std_dev.y() << "]\nparameters:\n"
       << YamlParameters(r.parameters, "  ") << "projection_diff:\n"
       << YamlDiff(r.diff, "  ") << "max_diff_px: " << r.max_diff_px
       << "\nresult: " << (r.pass ? "PASS" : "FAIL") << "\n";
  yaml << "causes:\n";
  for (const std::string& cause : r.causes) yaml << "  - " << Quoted(cause) << "\n";
  if (r.rerun_diff) {
    yaml << "rerun:\n  description: " << Quoted(r.rerun_description) << "\n  projection_diff:\n"
         << YamlDiff(*r.rerun_diff, "    ") << "  parameters:\n"
         << YamlParameters(r.rerun_parameters, "    ");
  }
  if (!r.cross_validations.empty()) yaml << "cross_validation:\n";
  for (const CrossValidation& cv : r.cross_validations) {
    yaml << "  - settings: " << Quoted(cv.settings) << "\n    worst_ratio: " << cv.worst_ratio
         << "\n    verdict: " << Quoted(cv.verdict) << "\n    pairs:\n";
    for (const FoldComparison& f : cv.pairs) {
      yaml << "      - {folds: [" << f.fold_a << ", " << f.fold_b << "], views: [" << f.views_a
           << ", " << f.views_b << "], mean_px: " << f.mean_px << ", p95_px: " << f.p95_px
           << ", predicted_mean_px: " << f.predicted_mean_px
           << ", predicted_p95_px: " << f.predicted_p95_px << "}\n";
    }
  }
  if (r.verdict) yaml << VerdictYaml(*r.verdict);
  const std::string text = CrossCheckText(r);
  WriteFileAtomically(dir / "cross_check.yaml", false,
                      [&](std::ostream& out) { out << yaml.str(); });
  WriteFileAtomically(dir / "cross_check.txt", false, [&](std::ostream& out) { out << text; });
  return text;
}

}  // namespace portcal
