// The rows of the COLMAP and portcal tables that are not features
// (colmap_ext/feature/: keypoints, matches, two-view geometries, markers),
// and COLMAP's image pair ids.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/feature/keypoint.h"
#include "colmap_ext/feature/marker_detection.h"
#include "colmap_ext/feature/two_view_geometry.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/util/types.h"

namespace portcal {

// A row of the images table.
struct DatabaseImage {
  image_t image_id = 0;
  std::string name;
  camera_t camera_id = kInvalidCameraId;
  // Optional pose prior (prior_qw..prior_tz); NULL columns when absent.
  std::optional<Rigid3d> cam_from_world_prior;
  // Optional position prior, the camera centre in the world (navigation,
  // GPS), metres: prior_tx..tz with prior_q NULL, as COLMAP 3.8 stores the
  // positions it reads from EXIF GPS. Ignored when cam_from_world_prior is
  // set (its centre is the position).
  std::optional<Eigen::Vector3d> position_prior;

  // The prior's camera centre, from either form.
  std::optional<Eigen::Vector3d> PriorPosition() const;
};

// portcal_target_observations: a target point seen in an image.
struct TargetObservation {
  int64_t point_id = 0;                                       // index on the target
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();               // COLMAP pixels
  Eigen::Vector3d point_in_target = Eigen::Vector3d::Zero();  // metres
};

// portcal_target_detections: the outcome of target detection in an image.
struct TargetDetectionStatus {
  std::string target;  // e.g. "chessboard 10x7"
  bool found = false;
  int num_points = 0;
  std::string reason;  // why not, when not found
};

// portcal_stage_log: one completed stage run.
struct StageLogEntry {
  int64_t run_id = 0;
  std::string stage;
  std::string options;     // the options as "name=value" lines
  std::string start_time;  // ISO 8601 UTC
  std::string end_time;
  std::string status;  // "succeeded"
  std::string counts;  // "name=value" lines
};

constexpr image_t kMaxNumImages = 2147483647;

// COLMAP's pair id: id1 * 2147483647 + id2 with id1 < id2.
image_pair_t ImagePairToPairId(image_t image_id1, image_t image_id2);
void PairIdToImagePair(image_pair_t pair_id, image_t* image_id1, image_t* image_id2);
bool SwapImagePair(image_t image_id1, image_t image_id2);

}  // namespace portcal
