#include <cstdio>
#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::string Num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string List(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + Num(values[i]);
  return text + "]";
}

// A YAML single-quoted scalar: a quote inside is doubled.
std::string SingleQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// Standard deviations: negative means undetermined, written as null.
std::string StdDevList(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    text += (i ? ", " : "") + (values[i] < 0 ? std::string("null") : Num(values[i]));
  }
  return text + "]";
}

std::string StdDevText(const std::vector<double>& values, size_t i) {
  if (i >= values.size() || values[i] == 0) return "          (fixed)";
  if (values[i] < 0) return "   (undetermined)";
  std::ostringstream out;
  out << std::fixed << std::setprecision(6) << std::setw(17) << values[i];
  return out.str();
}

// The report's two error figures, one line each: what they are, and why
// other tools print other numbers for the same fit.
std::string ErrorFiguresExplained(bool self_calibration) {
  return std::string(
             "  RMS reprojection error: the root mean square of the distances (pixels) between the "
             "observed and "
             "the reprojected points; the mean distance, which COLMAP's model_analyzer and "
             "portcal's mapper "
             "print, is smaller.\n") +
         (self_calibration ? "  Residual sigma: the noise of one pixel coordinate of a keypoint at "
                             "SIFT's finest scales that "
                             "the fit implies (coarser keypoints count less, by their scale), "
                             "corrected for the free "
                             "parameters; the standard deviations are scaled by it.\n"
                           : "  Residual sigma: the noise of one pixel coordinate that the fit "
                             "implies, sqrt(sum of squared "
                             "residuals / (2 x points - free parameters)); the standard deviations "
                             "are scaled by it.\n");
}

// The two estimates behind a std dev, when there are two.
std::string StdDevSourcesText(const std::vector<double>& by_noise,
                              const std::vector<double>& by_clusters, size_t i) {
  if (i >= by_noise.size() || i >= by_clusters.size() || by_noise[i] <= 0) return "";
  std::ostringstream out;
  out << std::fixed << std::setprecision(6) << std::setw(17) << by_noise[i] << std::setw(17)
      << by_clusters[i];
  return out.str();
}

// A covariance matrix under `key`, a flow list per row; nothing when empty.
std::string CovarianceYaml(const std::string& key, const Eigen::MatrixXd& covariance) {
  if (covariance.size() == 0) return "";
  std::string text = key + ":\n";
  for (Eigen::Index r = 0; r < covariance.rows(); ++r) {
    std::vector<double> row(static_cast<size_t>(covariance.cols()));
    for (Eigen::Index c = 0; c < covariance.cols(); ++c)
      row[static_cast<size_t>(c)] = covariance(r, c);
    text += "- " + List(row) + "\n";
  }
  return text;
}

// The rows of a grid's map, one flow list each.
std::string MapRows(const Eigen::MatrixXd& map, const std::string& indent) {
  std::string text;
  for (Eigen::Index r = 0; r < map.rows(); ++r) {
    std::vector<double> row(static_cast<size_t>(map.cols()));
    for (Eigen::Index c = 0; c < map.cols(); ++c) row[static_cast<size_t>(c)] = map(r, c);
    text += indent + "- " + List(row) + "\n";
  }
  return text;
}

std::string UncertaintyYaml(const ProjectionUncertaintyGrid& grid) {
  std::ostringstream out;
  out << "projection_uncertainty:\n"
      << "  definition: 'mrcal 2.2 projection_uncertainty, mean-frames, worstdirection-stdev (px); "
         "points at "
         "depth working_distance_m and at infinity; -1: no ray'\n"
      << "  of: " << grid.of << "\n"
      << "  determined: " << (grid.determined ? "true" : "false") << "\n"
      << "  working_distance_m: " << Num(grid.working_distance_m) << "\n"
      << "  pixel_sigma_px: " << Num(grid.pixel_sigma_px) << "\n"
      << "  x_px: " << List(grid.x_px) << "\n"
      << "  y_px: " << List(grid.y_px) << "\n"
      << "  at_working_distance_px:\n"
      << MapRows(grid.at_working_distance_px, "  ") << "  at_infinity_px:\n"
      << MapRows(grid.at_infinity_px, "  ");
  return out.str();
}

std::string Yaml(const CalibrationReport& r) {
  std::ostringstream out;
  out << "# portcal calibration report (calibmar-compatible keys first)\n";
  if (r.verdict) out << "# VERDICT: " << r.verdict->Summary() << "\n";
  for (const std::string& warning : r.warnings) out << "# WARNING: " << warning << "\n";
  out << "model: " << r.camera.ModelName() << "\n"
      << "parameters: " << List(r.camera.params) << "\n"
      << "non_svp_model: " << (r.housing ? r.housing->ModelName() : "NONE") << "\n"
      << "non_svp_parameters: " << List(r.housing ? r.housing->params : std::vector<double>{})
      << "\n"
      << "width: " << r.camera.width << "\n"
      << "height: " << r.camera.height << "\n"
      << "parameter_names: [" << r.camera.ParamsInfo() << "]\n"
      << "parameters_std_dev: " << StdDevList(r.parameters_std_dev) << "\n"
      << "non_svp_parameters_std_dev: " << StdDevList(r.housing_std_dev) << "\n";
  const std::pair<const char*, const std::vector<double>*> estimates[] = {
      {"parameters_std_dev_by_noise", &r.parameters_std_dev_by_noise},
      {"parameters_std_dev_by_clusters", &r.parameters_std_dev_by_clusters},
      {"non_svp_parameters_std_dev_by_noise", &r.housing_std_dev_by_noise},
      {"non_svp_parameters_std_dev_by_clusters", &r.housing_std_dev_by_clusters}};
  for (const auto& [key, values] : estimates) {
    if (!values->empty()) out << key << ": " << StdDevList(*values) << "\n";
  }
  out << CovarianceYaml("parameters_covariance", r.parameters_covariance)
      << CovarianceYaml("non_svp_parameters_covariance", r.housing_covariance);
  out << "overall_rms: " << Num(r.overall_rms_px) << "\n"
      << "residual_sigma_px: " << Num(r.residual_sigma_px) << "\n"
      << "num_views: "
      << std::count_if(r.views.begin(), r.views.end(),
                       [](const CalibratedView& v) { return !v.dropped; })
      << "\nnum_points: " << r.num_points << "\n"
      << "target: " << SingleQuoted(r.target_description) << "\n";
  if (r.board_warp) {
    out << "board_warp: " << List({r.board_warp->x(), r.board_warp->y()}) << "\n"
        << "board_warp_std_dev: " << List({r.board_warp_std_dev->x(), r.board_warp_std_dev->y()})
        << "\n";
  }
  if (!r.warnings.empty()) {
    out << "warnings:\n";
    for (const std::string& warning : r.warnings) out << "- " << SingleQuoted(warning) << "\n";
  }
  if (!r.notes.empty()) {
    out << "notes:\n";
    for (const std::string& note : r.notes) out << "- " << SingleQuoted(note) << "\n";
  }
  if (r.verdict) out << VerdictYaml(*r.verdict);
  if (r.projection_uncertainty) out << UncertaintyYaml(*r.projection_uncertainty);
  out << "per_view:\n";
  for (const CalibratedView& v : r.views) {
    const Eigen::Vector4d q = QuaternionToWxyz(v.cam_from_target.rotation);
    out << "- image: " << YamlQuoted(v.image_name) << "\n  rms: " << Num(v.rms_px)
        << "\n  points: " << v.num_points << "\n  outlier: " << (v.outlier ? "true" : "false")
        << "\n  dropped: " << (v.dropped ? "true" : "false") << "\n  cam_from_" << r.pose_frame
        << ":\n    rotation_wxyz: " << List({q[0], q[1], q[2], q[3]}) << "\n    translation: "
        << List({v.cam_from_target.translation.x(), v.cam_from_target.translation.y(),
                 v.cam_from_target.translation.z()})
        << "\n";
  }
  return out.str();
}

std::string Text(const CalibrationReport& r) {
  std::ostringstream out;
  out << std::fixed;
  out << "portcal calibration\n===================\n\n";
  if (r.verdict) out << VerdictText(*r.verdict) << "\n";
  for (const std::string& warning : r.warnings) out << "WARNING: " << warning << "\n\n";
  out << "Camera model " << r.camera.ModelName() << ", " << r.camera.width << " x "
      << r.camera.height << " px\nTarget: " << r.target_description << "\n\n";
  const std::vector<std::string> names = SplitTokens(r.camera.ParamsInfo(), ", ");
  out << "  parameter          value          std dev"
      << (r.parameters_std_dev_by_clusters.empty() && r.housing_std_dev_by_clusters.empty()
              ? ""
              : "   (by the noise, by the clusters' spread)")
      << "\n";
  for (size_t i = 0; i < r.camera.params.size(); ++i) {
    out << "  " << std::left << std::setw(10) << names[i] << std::right << std::setw(17)
        << std::setprecision(6) << r.camera.params[i] << StdDevText(r.parameters_std_dev, i)
        << StdDevSourcesText(r.parameters_std_dev_by_noise, r.parameters_std_dev_by_clusters, i)
        << "\n";
  }
  if (r.housing) {
    const std::vector<std::string> housing_names = SplitTokens(r.housing->ParamsInfo(), ", ");
    out << "\nHousing " << r.housing->ModelName() << " (metres)\n";
    const HousingRefinement refinement = r.housing->Refinement();
    for (size_t i = 0; i < r.housing->params.size(); ++i) {
      // Thickness, radius, indices: the user's constants, never refined.
      const bool constant = !refinement.IsRefined(static_cast<int>(i));
      out << "  " << std::left << std::setw(10) << housing_names[i] << std::right << std::setw(17)
          << std::setprecision(6) << r.housing->params[i]
          << (i < r.housing_std_dev.size() && r.housing_std_dev[i] == 0 && constant
                  ? std::string("       (constant)")
                  : StdDevText(r.housing_std_dev, i) +
                        StdDevSourcesText(r.housing_std_dev_by_noise, r.housing_std_dev_by_clusters,
                                          i))
          << "\n";
    }
    out << "  In words: " << r.housing->InWords() << ".\n";
  }
  if (r.board_warp) {
    out << std::setprecision(3) << "\nBoard warp (parabolic sag): x " << r.board_warp->x() * 1000
        << " +- " << r.board_warp_std_dev->x() * 1000 << " mm, y " << r.board_warp->y() * 1000
        << " +- " << r.board_warp_std_dev->y() * 1000 << " mm\n";
  }
  for (const std::string& note : r.notes) out << "\nNote: " << note << "\n";
  if (r.projection_uncertainty && r.projection_uncertainty->determined) {
    const ProjectionUncertaintyGrid& u = *r.projection_uncertainty;
    out << std::setprecision(3) << "\nProjection uncertainty of the " << u.of
        << " (mrcal's mean-frames, worst "
        << "direction, 1 sigma): mean " << u.Mean(false) << ", max " << u.Max(false) << " px at "
        << u.working_distance_m << " m; mean " << u.Mean(true) << ", max " << u.Max(true)
        << " px at infinity\n";
  }
  out << std::setprecision(4) << "\nRMS reprojection error " << r.overall_rms_px << " px over "
      << r.num_points << " points (residual sigma " << r.residual_sigma_px << " px)\n"
      << ErrorFiguresExplained(r.pose_frame == "world") << "\n"
      << "  view                                  rms (px)  points\n";
  for (const CalibratedView& v : r.views) {
    out << "  " << std::left << std::setw(36) << v.image_name << std::right << std::setw(10)
        << v.rms_px << std::setw(8) << v.num_points
        << (v.dropped   ? "  dropped (outlier)"
            : v.outlier ? "  outlier"
                        : "")
        << "\n";
  }
  return out.str();
}

std::string CameraBlock(const std::string& key, const Camera& camera,
                        const std::vector<double>& std_dev, const std::optional<Housing>& housing) {
  std::ostringstream out;
  out << key << ":\n  model: " << camera.ModelName() << "\n  parameters: " << List(camera.params)
      << "\n  parameters_std_dev: " << StdDevList(std_dev)
      << "\n  non_svp_model: " << (housing ? housing->ModelName() : "NONE")
      << "\n  non_svp_parameters: " << List(housing ? housing->params : std::vector<double>{})
      << "\n  width: " << camera.width << "\n  height: " << camera.height << "\n";
  return out.str();
}

}  // namespace

double ProjectionUncertaintyGrid::Mean(bool at_infinity) const {
  const Eigen::MatrixXd& map = at_infinity ? at_infinity_px : at_working_distance_px;
  double sum = 0;
  int count = 0;
  for (Eigen::Index k = 0; k < map.size(); ++k) {
    if (map(k) >= 0) sum += map(k), ++count;
  }
  return count > 0 ? sum / count : -1;
}

double ProjectionUncertaintyGrid::Max(bool at_infinity) const {
  const Eigen::MatrixXd& map = at_infinity ? at_infinity_px : at_working_distance_px;
  return map.size() > 0 ? map.maxCoeff() : -1;
}

std::string WriteStereoCalibrationReport(const StereoCalibrationResult& r,
                                         const HousedCamera& camera1, const HousedCamera& camera2,
                                         const std::string& target_description, const fs::path& dir,
                                         const CalibrationVerdict* verdict) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": cannot create output directory");
  const Rigid3d cam1_from_cam2 = r.cam2_from_cam1.Inverse();
  const Eigen::Matrix3d rotation = cam1_from_cam2.rotation.toRotationMatrix();
  const Eigen::Vector4d q = QuaternionToWxyz(r.cam2_from_cam1.rotation.normalized());
  std::ostringstream yaml;
  yaml << "# portcal stereo calibration report (calibmar-compatible keys first)\n"
       << "cam_to_world_rotation_rowmajor: "
       << List({rotation(0, 0), rotation(0, 1), rotation(0, 2), rotation(1, 0), rotation(1, 1),
                rotation(1, 2), rotation(2, 0), rotation(2, 1), rotation(2, 2)})
       << "\ncam_to_world_translation: "
       << List({cam1_from_cam2.translation.x(), cam1_from_cam2.translation.y(),
                cam1_from_cam2.translation.z()})
       << "\ncam2_from_cam1:\n  rotation_wxyz: " << List({q[0], q[1], q[2], q[3]})
       << "\n  translation: "
       << List({r.cam2_from_cam1.translation.x(), r.cam2_from_cam1.translation.y(),
                r.cam2_from_cam1.translation.z()})
       << "\ncam2_from_cam1_std_dev:\n  rotation_deg: "
       << StdDevList(
              {r.rotation_std_dev_deg.x(), r.rotation_std_dev_deg.y(), r.rotation_std_dev_deg.z()})
       << "\n  translation: "
       << StdDevList(
              {r.translation_std_dev.x(), r.translation_std_dev.y(), r.translation_std_dev.z()})
       << "\nbaseline: " << Num(r.cam2_from_cam1.translation.norm()) << "\n"
       << CameraBlock("camera1", r.camera1, r.camera1_std_dev, camera1.housing)
       << CameraBlock("camera2", r.camera2, r.camera2_std_dev, camera2.housing)
       << "overall_rms: " << Num(r.overall_rms_px)
       << "\nresidual_sigma_px: " << Num(r.residual_sigma_px) << "\nnum_views: " << r.views1.size()
       << "\nnum_points: " << r.num_points << "\ntarget: '" << target_description
       << "'\nper_view:\n";
  for (size_t f = 0; f < r.views1.size(); ++f) {
    yaml << "- image1: " << YamlQuoted(r.views1[f].image_name)
         << "\n  rms1: " << Num(r.views1[f].rms_px)
         << "\n  image2: " << YamlQuoted(r.views2[f].image_name)
         << "\n  rms2: " << Num(r.views2[f].rms_px) << "\n";
  }
  std::ostringstream text;
  if (verdict) yaml << VerdictYaml(*verdict);
  text << "portcal stereo calibration\n==========================\n\n"
       << (verdict ? VerdictText(*verdict) + "\n" : "");
  text << std::fixed << "Target: " << target_description
       << "\n\ncam2_from_cam1 (camera 2 from camera 1)\n"
       << std::setprecision(6) << "  rotation (w, x, y, z)   " << q[0] << " " << q[1] << " " << q[2]
       << " " << q[3] << "\n  translation (m)         " << r.cam2_from_cam1.translation.transpose()
       << "\n  baseline (m)            " << r.cam2_from_cam1.translation.norm() << std::scientific
       << std::setprecision(2) << "\n  rotation std dev (deg)  "
       << r.rotation_std_dev_deg.transpose() << "\n  translation std dev (m) "
       << r.translation_std_dev.transpose() << std::fixed << "\n\n";
  for (const auto& [name, camera, std_dev] :
       {std::tuple{"camera 1", &r.camera1, &r.camera1_std_dev},
        std::tuple{"camera 2", &r.camera2, &r.camera2_std_dev}}) {
    text << name << " " << camera->ModelName() << ": ";
    for (double p : camera->params) text << std::setprecision(6) << p << " ";
    text << (std_dev->empty() || (*std_dev)[0] == 0 ? "(fixed)" : "(refined)") << "\n";
  }
  text << std::setprecision(4) << "\nRMS reprojection error " << r.overall_rms_px << " px over "
       << r.num_points << " points\n\n  frame  image 1 rms  image 2 rms\n";
  for (size_t f = 0; f < r.views1.size(); ++f) {
    text << "  " << std::left << std::setw(24) << r.views1[f].image_name << std::right
         << std::setw(8) << r.views1[f].rms_px << std::setw(10) << r.views2[f].rms_px << "\n";
  }
  const std::string yaml_text = yaml.str(), text_text = text.str();
  WriteFileAtomically(dir / "calibration.yaml", false,
                      [&](std::ostream& out) { out << yaml_text; });
  WriteFileAtomically(dir / "calibration.txt", false, [&](std::ostream& out) { out << text_text; });
  return text_text;
}

std::string CalibrationReportText(const CalibrationReport& report) { return Text(report); }

void WriteCalibrationReport(const CalibrationReport& report, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": cannot create output directory");
  const std::string yaml = Yaml(report), text = Text(report);
  WriteFileAtomically(dir / "calibration.yaml", false, [&](std::ostream& out) { out << yaml; });
  WriteFileAtomically(dir / "calibration.txt", false, [&](std::ostream& out) { out << text; });
}

}  // namespace portcal
