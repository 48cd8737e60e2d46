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

// Throws InputError naming the database when it holds no observations.
TargetViews ReadTargetViews(Database* database);

// The camera to calibrate: `camera_id` if >= 0 (must have views), else the
// only camera with views. Throws InputError naming the database and
// `option`, the flag that chooses the camera.
camera_t ChooseCamera(const TargetViews& views, int camera_id, const std::string& database_path,
                      const std::string& option = "--camera_id");

}  // namespace portcal
