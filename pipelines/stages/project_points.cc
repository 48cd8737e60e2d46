#include "pipelines/stages/project_points.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {

void ProjectPointsOptions::Check() const {
  if (points_path.empty()) {
    throw OptionError("--points_path", "''", "a text file of points or pixels");
  }
  const int num_sources = !input_path.empty() + !input_calibration.empty() + !camera_model.empty();
  if (num_sources != 1) {
    throw InputError(
        std::string(num_sources == 0 ? "no camera given" : "more than one camera given") +
        ": give one of --input_path (a sparse model), --input_calibration (a calibration file) or "
        "--Camera.model with --Camera.params, --Camera.width and --Camera.height");
  }
  if (!input_path.empty() && housing) {
    throw OptionError("--Housing.model", housing->ModelName(),
                      "not with --input_path (its housings.txt says)");
  }
  if (housing) housing->ValidateInput("--Housing.params");
  if (!camera_model.empty()) {
    if (!ExistsCameraModelWithName(camera_model)) {
      throw OptionError("--Camera.model", "'" + camera_model + "'", "one of " + CameraModelNames());
    }
    if (width <= 0) throw OptionError("--Camera.width", width, "> 0");
    if (height <= 0) throw OptionError("--Camera.height", height, "> 0");
  }
}

namespace {

// The camera `camera_id` of the model (-1: its only camera), with its housing.
HousedCamera CameraOfModel(const std::string& input_path, int camera_id) {
  const SparseModel model = ReadSparseModel(input_path);
  camera_t id = static_cast<camera_t>(camera_id);
  if (camera_id < 0) {
    if (model.cameras.size() != 1) {
      std::string ids;
      for (const auto& [each, camera] : model.cameras)
        ids += (ids.empty() ? "" : ", ") + std::to_string(each);
      throw OptionError("--camera_id", "-1 (the only camera)",
                        "the id of one of the " + std::to_string(model.cameras.size()) +
                            " cameras of " + input_path + " (" + ids + ")");
    }
    id = model.cameras.begin()->first;
  }
  const auto it = model.cameras.find(id);
  if (it == model.cameras.end()) {
    throw InputError(input_path + ": no camera with id " + std::to_string(camera_id) +
                     " (--camera_id)");
  }
  HousedCamera housed;
  housed.camera = it->second;
  const auto housing_it = model.housings.find(id);
  if (housing_it != model.housings.end()) housed.housing = housing_it->second;
  return housed;
}

HousedCamera LoadCamera(const ProjectPointsOptions& options) {
  if (!options.input_path.empty()) return CameraOfModel(options.input_path, options.camera_id);
  HousedCamera housed;
  if (!options.input_calibration.empty()) {
    const CalibrationReport report = ReadCalibrationReport(options.input_calibration);
    housed.camera = report.camera;
    housed.housing = options.housing ? options.housing : report.housing;
    return housed;
  }
  Camera& camera = housed.camera;
  camera.model_id = CameraModelNameToId(options.camera_model);
  camera.width = options.width;
  camera.height = options.height;
  camera.params = ParseDoubleList(options.camera_params, "--Camera.params");
  camera.Validate("--Camera.params");
  housed.housing = options.housing;
  return housed;
}

// One output line for one input line's values, or nullopt without an answer.
std::optional<std::string> Answer(const HousedCamera& camera, const std::vector<double>& values,
                                  bool unproject) {
  std::ostringstream out;
  out << std::setprecision(17);
  if (unproject) {
    const std::optional<Ray3d> ray = camera.Unproject(Eigen::Vector2d(values[0], values[1]));
    if (!ray) return std::nullopt;
    out << ray->origin.x() << " " << ray->origin.y() << " " << ray->origin.z() << " "
        << ray->direction.x() << " " << ray->direction.y() << " " << ray->direction.z();
  } else {
    const std::optional<Eigen::Vector2d> pixel =
        camera.Project(Eigen::Vector3d(values[0], values[1], values[2]));
    if (!pixel) return std::nullopt;
    out << pixel->x() << " " << pixel->y();
  }
  return out.str();
}

}  // namespace

ProjectPointsSummary RunProjectPoints(const ProjectPointsOptions& options, ProgressSink& progress) {
  options.Check();
  const HousedCamera camera = LoadCamera(options);
  if (!std::filesystem::is_regular_file(options.points_path)) {
    throw InputError(options.points_path + ": not a file of points (--points_path)");
  }
  std::ifstream in(options.points_path);
  if (!in) throw InputError(options.points_path + ": cannot open");
  const size_t expected = options.unproject ? 2 : 3;
  ProjectPointsSummary summary;
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::string where = options.points_path + ":" + std::to_string(line_number);
    const std::vector<double> values = ParseDoubleList(trimmed, where);
    if (values.size() != expected) {
      throw InputError(where + ": expected " +
                       (options.unproject ? std::string("x y (pixels)")
                                          : std::string("X Y Z (metres, camera frame)")));
    }
    std::optional<std::string> answer = Answer(camera, values, options.unproject);
    if (!answer) {
      ++summary.num_invalid;
      answer =
          options.unproject
              ? "invalid no ray (distortion not invertible or total internal reflection)"
              : "invalid not visible (behind the camera, inside the housing or totally reflected)";
    }
    summary.lines.push_back(std::move(*answer));
  }
  return summary;
}

}  // namespace portcal
