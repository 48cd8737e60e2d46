// Reading calibration files back: portcal's and calibmar's
// calibration.yaml, and a camera alone from OpenCV's, ROS's and mrcal's.
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <regex>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/opencv_camera_file.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr const char* kCalibrationFormats =
    "portcal reads portcal's and calibmar's calibration.yaml (key 'model'), OpenCV's FileStorage "
    "YAML and ROS "
    "camera_info YAML (key 'camera_matrix'), and mrcal's .cameramodel";

// A camera from another tool's file: no standard deviations, views or
// housing.
CalibrationReport ReportOfCamera(const Camera& camera) {
  CalibrationReport report;
  report.camera = camera;
  return report;
}

// calibmar writes the standard deviations, the RMS and the target as
// comments ("# non_svp_est_std_dev: a, b, ...", "# overall_rms: x",
// "# target: ..."), not as keys: taken where the keys are absent.
void ReadCalibmarComments(const fs::path& path, CalibrationReport* report) {
  std::ifstream in(path);
  const std::regex comment(R"(^#\s*(non_svp_est_std_dev|overall_rms|target)\s*:\s*(.*\S)\s*$)");
  std::smatch match;
  for (std::string line; std::getline(in, line);) {
    if (!std::regex_match(line, match, comment)) continue;
    const std::string key = match[1], value = match[2];
    try {
      if (key == "target" && report->target_description.empty()) {
        report->target_description = value;
      } else if (key == "overall_rms" && report->overall_rms_px == 0) {
        report->overall_rms_px = std::stod(value);
      } else if (key == "non_svp_est_std_dev" && report->housing &&
                 report->housing_std_dev.empty()) {
        for (const std::string& token : SplitTokens(value, ", "))
          report->housing_std_dev.push_back(std::stod(token));
        if (report->housing_std_dev.size() != report->housing->params.size()) {
          throw InputError(path.string() + ": the comment non_svp_est_std_dev has " +
                           std::to_string(report->housing_std_dev.size()) +
                           " values, non_svp_parameters " +
                           std::to_string(report->housing->params.size()));
        }
      }
    } catch (const std::logic_error&) {  // std::stod: not a number
      throw InputError(path.string() + ": the comment '" + line + "' does not hold numbers");
    }
  }
}

// A covariance under `key` (absent: empty): `size` rows of `size` finite
// numbers, symmetric, its diagonal not negative.
Eigen::MatrixXd ReadCovariance(const YAML::Node& root, const char* key, size_t size,
                               const fs::path& path) {
  if (!root[key]) return Eigen::MatrixXd();
  const auto rows = root[key].as<std::vector<std::vector<double>>>();
  const Eigen::Index n = static_cast<Eigen::Index>(size);
  Eigen::MatrixXd covariance(n, n);
  if (rows.size() != size) {
    throw InputError(path.string() + ": " + key + " has " + std::to_string(rows.size()) +
                     " rows, not " + std::to_string(size));
  }
  for (size_t r = 0; r < size; ++r) {
    if (rows[r].size() != size) {
      throw InputError(path.string() + ": " + key + " row " + std::to_string(r) + " has " +
                       std::to_string(rows[r].size()) + " values, not " + std::to_string(size));
    }
    for (size_t c = 0; c < size; ++c)
      covariance(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = rows[r][c];
  }
  const double scale = std::max(1e-300, covariance.cwiseAbs().maxCoeff());
  if (!covariance.allFinite() || (covariance.diagonal().array() < 0).any() ||
      !((covariance - covariance.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale)) {
    throw InputError(path.string() + ": " + key +
                     " is not a covariance (finite, symmetric, diagonal >= 0)");
  }
  return covariance;
}

}  // namespace

namespace {

// The body of ReadCalibrationReport; yaml-cpp's exceptions (a key looked up in a scalar, a
// value of the wrong type) are turned into InputError by the caller.
CalibrationReport ReadCalibrationReportUnguarded(const fs::path& path) {
  if (!fs::exists(path)) throw InputError(path.string() + ": no such file");
  if (!fs::is_regular_file(path))
    throw InputError(path.string() + ": not a file (" + kCalibrationFormats + ")");
  if (path.extension() == ".cameramodel") return ReportOfCamera(ReadMrcalCameraModel(path).camera);
  if (IsOpenCvOrRosCameraYaml(path)) return ReportOfCamera(ReadOpenCvCameraYaml(path));
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what() + " (" + kCalibrationFormats + ")");
  }
  for (const char* key : {"model", "width", "height", "parameters"}) {
    if (!root.IsMap() || !root[key]) {
      throw InputError(path.string() + ": no key '" + key + "'; " + kCalibrationFormats);
    }
  }
  CalibrationReport report;
  try {
    try {
      report.camera.model_id = CameraModelNameToId(root["model"].as<std::string>());
    } catch (const InputError& e) {
      throw InputError(path.string() + ": model: " + e.what());
    }
    report.camera.width = root["width"].as<uint64_t>();
    report.camera.height = root["height"].as<uint64_t>();
    report.camera.params = root["parameters"].as<std::vector<double>>();
    if (root["non_svp_model"] && root["non_svp_model"].as<std::string>() != "NONE") {
      report.housing = Housing::FromName(root["non_svp_model"].as<std::string>(),
                                         root["non_svp_parameters"].as<std::vector<double>>(),
                                         path.string() + ": non_svp_parameters");
      report.housing->ValidateInput(path.string() + ": non_svp_parameters");
    }
    // portcal's own keys (absent in calibmar's files).
    if (root["parameters_std_dev"]) {
      for (const YAML::Node& value : root["parameters_std_dev"]) {
        report.parameters_std_dev.push_back(value.IsNull() ? -1.0 : value.as<double>());
      }
    }
    report.parameters_covariance =
        ReadCovariance(root, "parameters_covariance", report.camera.params.size(), path);
    if (report.housing) {
      report.housing_covariance = ReadCovariance(root, "non_svp_parameters_covariance",
                                                 report.housing->params.size(), path);
    }
    if (root["overall_rms"]) report.overall_rms_px = root["overall_rms"].as<double>();
    if (root["residual_sigma_px"])
      report.residual_sigma_px = root["residual_sigma_px"].as<double>();
    if (root["num_points"]) report.num_points = root["num_points"].as<int>();
    if (root["per_view"]) {
      for (const YAML::Node& entry : root["per_view"]) {
        CalibratedView view;
        view.image_name = entry["image"].as<std::string>();
        if (entry["rms"]) view.rms_px = entry["rms"].as<double>();
        if (entry["points"]) view.num_points = entry["points"].as<int>();
        if (entry["outlier"]) view.outlier = entry["outlier"].as<bool>();
        if (entry["dropped"]) view.dropped = entry["dropped"].as<bool>();
        report.views.push_back(view);
      }
    }
    if (root["board_warp"] && root["board_warp_std_dev"]) {
      const auto warp = root["board_warp"].as<std::vector<double>>();
      const auto warp_std_dev = root["board_warp_std_dev"].as<std::vector<double>>();
      if (warp.size() != 2 || warp_std_dev.size() != 2) {
        throw InputError(path.string() + ": board_warp and board_warp_std_dev need 2 values each");
      }
      report.board_warp = Eigen::Vector2d(warp[0], warp[1]);
      report.board_warp_std_dev = Eigen::Vector2d(warp_std_dev[0], warp_std_dev[1]);
    }
    if (root["target"]) report.target_description = root["target"].as<std::string>();
    if (root["notes"]) report.notes = root["notes"].as<std::vector<std::string>>();
    if (root["warnings"]) report.warnings = root["warnings"].as<std::vector<std::string>>();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  ReadCalibmarComments(path, &report);
  report.camera.Validate(path.string());
  return report;
}

}  // namespace

CalibrationReport ReadCalibrationReport(const fs::path& path) {
  try {
    return ReadCalibrationReportUnguarded(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

}  // namespace portcal
