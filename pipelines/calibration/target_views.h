// The target observations target_extractor stored, as calibration views
// grouped by camera (views of images whose target was found).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

struct TargetViews {
  std::map<camera_t, std::vector<CalibrationView>> by_camera;
  std::string target;  // target_extractor's description, e.g. "chessboard 8x6"
};

// Throws InputError naming the database when it holds no observations,
// or an observation no detector writes (non-finite, far off the image).
TargetViews ReadTargetViews(Database* database);
// The same, empty where the database holds no observations yet (a plan
// before the first view); a damaged observation is still an error.
TargetViews ReadTargetViewsIfAny(Database* database);

// The camera to calibrate: `camera_id` if >= 0 (must have views), else the
// only camera with views. Throws InputError naming the database and
// `option`, the flag that chooses the camera.
camera_t ChooseCamera(const TargetViews& views, int camera_id, const std::string& database_path,
                      const std::string& option = "--camera_id");

}  // namespace portcal
