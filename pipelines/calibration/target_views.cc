#include "pipelines/calibration/target_views.h"

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

// Detected corners lie in the image; one more than an image size outside it
// is a damaged row, not a measurement.
bool NearTheImage(const Eigen::Vector2d& xy, const Camera& camera) {
  const double w = static_cast<double>(camera.width), h = static_cast<double>(camera.height);
  return xy.x() > -w && xy.x() < 2 * w && xy.y() > -h && xy.y() < 2 * h;
}

}  // namespace

TargetViews ReadTargetViews(Database* database) {
  TargetViews views = ReadTargetViewsIfAny(database);
  if (views.by_camera.empty()) {
    throw InputError(database->path() + ": no target observations; run target_extractor first");
  }
  return views;
}

TargetViews ReadTargetViewsIfAny(Database* database) {
  TargetViews views;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    const auto status = database->ReadTargetDetectionStatus(image.image_id);
    if (!status || !status->found) continue;
    views.target = status->target;
    CalibrationView view;
    view.image_name = image.name;
    const std::optional<Camera> camera = database->ReadCamera(image.camera_id);
    for (const TargetObservation& o : database->ReadTargetObservations(image.image_id)) {
      // A value no detector writes (an edited or damaged row) would
      // otherwise surface as a solver that "did not converge".
      const std::string where = database->path() + ": image " + image.name + ", target point " +
                                std::to_string(o.point_id) + " of portcal_target_observations";
      if (!o.xy.allFinite() || !o.point_in_target.allFinite())
        throw InputError(where + " is not a finite number");
      if (camera && !NearTheImage(o.xy, *camera)) {
        throw InputError(where + " is at (" + std::to_string(o.xy.x()) + ", " +
                         std::to_string(o.xy.y()) + "), far outside the " +
                         std::to_string(camera->width) + "x" + std::to_string(camera->height) +
                         " image");
      }
      view.points_in_target.push_back(o.point_in_target);
      view.pixels.push_back(o.xy);
    }
    views.by_camera[image.camera_id].push_back(std::move(view));
  }
  return views;
}

camera_t ChooseCamera(const TargetViews& views, int camera_id, const std::string& database_path,
                      const std::string& option) {
  if (camera_id >= 0) {
    if (!views.by_camera.count(static_cast<camera_t>(camera_id))) {
      throw InputError(database_path + ": camera " + std::to_string(camera_id) + " (" + option +
                       ") has no target observations");
    }
    return static_cast<camera_t>(camera_id);
  }
  if (views.by_camera.size() > 1) {
    throw InputError(database_path + ": " + std::to_string(views.by_camera.size()) +
                     " cameras have target observations; choose one with " + option +
                     " (or "
                     "extract with --ImageReader.single_camera 1)");
  }
  return views.by_camera.begin()->first;
}

}  // namespace portcal
