// A target detection as database rows: the corners
// (portcal_target_observations), the markers seen, and the per-image status
// (portcal_target_detections). target_extractor and the live calibrator
// write the same rows this way.
#pragma once

#include <string>

#include "colmap_ext/util/types.h"
#include "database/database.h"
#include "pipelines/detection/target_detector.h"

namespace portcal {

// The target as the status names it, e.g. "chessboard 10x7 inner corners,
// square 0.02 m".
std::string TargetDescriptionText(const TargetDetectorOptions& options);

// The status's reason: "found", with the symmetric-board warning and the
// corners left out, or why not.
std::string DetectionStatusText(const TargetDetection& detection);

// Replaces the image's corners, markers and status. Call inside the
// stage's transaction.
void WriteTargetDetection(Database* database, image_t image_id, const TargetDetection& detection,
                          const std::string& target);

}  // namespace portcal
