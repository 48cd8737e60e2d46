#include "pipelines/calibration/target_views.h"

#include "colmap_ext/util/error.h"

namespace portcal {

TargetViews ReadTargetViews(Database* database) {
  TargetViews views;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    const auto status = database->ReadTargetDetectionStatus(image.image_id);
    if (!status || !status->found) continue;
    views.target = status->target;
    CalibrationView view;
    view.image_name = image.name;
    for (const TargetObservation& o : database->ReadTargetObservations(image.image_id)) {
      // A value no detector writes (an edited or damaged row) would
      // otherwise surface as a solver that "did not converge".
      if (!o.xy.allFinite() || !o.point_in_target.allFinite()) {
        throw InputError(database->path() + ": image " + image.name + ", target point " +
                         std::to_string(view.pixels.size()) + " of portcal_target_observations is not a finite number");
      }
      view.points_in_target.push_back(o.point_in_target);
      view.pixels.push_back(o.xy);
    }
    views.by_camera[image.camera_id].push_back(std::move(view));
  }
  if (views.by_camera.empty()) {
    throw InputError(database->path() + ": no target observations; run target_extractor first");
  }
  return views;
}

camera_t ChooseCamera(const TargetViews& views, int camera_id, const std::string& database_path) {
  if (camera_id >= 0) {
    if (!views.by_camera.count(static_cast<camera_t>(camera_id))) {
      throw InputError(database_path + ": camera " + std::to_string(camera_id) +
                       " (--camera_id) has no target observations");
    }
    return static_cast<camera_t>(camera_id);
  }
  if (views.by_camera.size() > 1) {
    throw InputError(database_path + ": " + std::to_string(views.by_camera.size()) +
                     " cameras have target observations; choose one with --camera_id (or "
                     "extract with --ImageReader.single_camera 1)");
  }
  return views.by_camera.begin()->first;
}

}  // namespace portcal
