#include "pipelines/stages/project_points.h"

#include <fstream>
#include <iomanip>
#include <optional>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

void ProjectPointsOptions::Check() const {
  if (points_path.empty()) {
    throw OptionError("--points_path", "''", "a text file of points or pixels");
  }
  if (!input_path.empty()) {
    if (camera_id < 0) {
      throw OptionError("--camera_id", std::to_string(camera_id),
                        "the id of a camera of --input_path");
    }
    return;
  }
  if (!ExistsCameraModelWithName(camera_model)) {
    throw OptionError("--Camera.model", "'" + camera_model + "'",
                      "one of " + CameraModelNames() + " (or give --input_path)");
  }
  if (width <= 0) throw OptionError("--Camera.width", std::to_string(width), "> 0");
  if (height <= 0) throw OptionError("--Camera.height", std::to_string(height), "> 0");
  if (!housing_model.empty() && housing_model != "NONE" &&
      !ExistsHousingModelWithName(housing_model)) {
    throw OptionError("--Housing.model", housing_model, "NONE, FLATPORT or DOMEPORT");
  }
}

namespace {

void LoadCamera(const ProjectPointsOptions& options, Camera* camera,
                std::optional<Housing>* housing) {
  if (!options.input_path.empty()) {
    const SparseModel model = ReadSparseModel(options.input_path);
    const auto it = model.cameras.find(static_cast<camera_t>(options.camera_id));
    if (it == model.cameras.end()) {
      throw InputError(options.input_path + ": no camera with id " +
                       std::to_string(options.camera_id));
    }
    *camera = it->second;
    const auto housing_it = model.housings.find(camera->camera_id);
    if (housing_it != model.housings.end()) *housing = housing_it->second;
    return;
  }
  camera->model_id = CameraModelNameToId(options.camera_model);
  camera->width = options.width;
  camera->height = options.height;
  camera->params = ParseDoubleList(options.camera_params, "--Camera.params");
  camera->Validate("--Camera.params");
  if (!options.housing_model.empty() && options.housing_model != "NONE") {
    *housing = Housing::FromName(
        options.housing_model,
        ParseDoubleList(options.housing_params, "--Housing.params"),
        "--Housing.params");
  }
}

}  // namespace

int ProjectPoints(const ProjectPointsOptions& options, std::ostream& out) {
  options.Check();
  Camera camera;
  std::optional<Housing> housing;
  LoadCamera(options, &camera, &housing);
  const Housing* housing_ptr = housing ? &*housing : nullptr;

  std::ifstream in(options.points_path);
  if (!in) throw InputError(options.points_path + ": cannot open");
  const size_t expected = options.unproject ? 2 : 3;
  out << std::setprecision(17);
  int num_invalid = 0;
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
    if (options.unproject) {
      const std::optional<Ray3d> ray =
          UnprojectPixel(camera, housing_ptr, Eigen::Vector2d(values[0], values[1]));
      if (!ray) {
        out << "invalid no ray (distortion not invertible or total internal "
               "reflection)\n";
        ++num_invalid;
        continue;
      }
      out << ray->origin.x() << " " << ray->origin.y() << " " << ray->origin.z() << " "
          << ray->direction.x() << " " << ray->direction.y() << " "
          << ray->direction.z() << "\n";
    } else {
      const std::optional<Eigen::Vector2d> pixel = ProjectPoint(
          camera, housing_ptr, Eigen::Vector3d(values[0], values[1], values[2]));
      if (!pixel) {
        out << "invalid not visible (behind the camera, inside the housing or "
               "totally reflected)\n";
        ++num_invalid;
        continue;
      }
      out << pixel->x() << " " << pixel->y() << "\n";
    }
  }
  return num_invalid;
}

}  // namespace portcal
