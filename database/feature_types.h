// What the COLMAP tables hold, in memory.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

using image_t = uint32_t;
using image_pair_t = uint64_t;

// COLMAP's SIFT keypoint: position (COLMAP pixels) and the affine shape
// [a11 a12; a21 a22] (scale and orientation).
struct FeatureKeypoint {
  float x = 0, y = 0;
  float a11 = 1, a12 = 0, a21 = 0, a22 = 1;

  static FeatureKeypoint FromScaleOrientation(float x, float y, float scale,
                                              float orientation);
  float ComputeScale() const;
  float ComputeOrientation() const;
};
using FeatureKeypoints = std::vector<FeatureKeypoint>;

// One row per keypoint, 128 uint8 columns (COLMAP's normalisation).
using FeatureDescriptors =
    Eigen::Matrix<uint8_t, Eigen::Dynamic, 128, Eigen::RowMajor>;

struct FeatureMatch {
  uint32_t point2D_idx1 = 0;
  uint32_t point2D_idx2 = 0;
};
using FeatureMatches = std::vector<FeatureMatch>;

// Values of two_view_geometries.config, as in COLMAP 3.8.
enum class TwoViewGeometryConfig : int {
  kUndefined = 0,
  kDegenerate = 1,
  kCalibrated = 2,
  kUncalibrated = 3,
  kPlanar = 4,
  kPanoramic = 5,
  kPlanarOrPanoramic = 6,
  kWatermark = 7,
  kMultiple = 8,
};

struct TwoViewGeometry {
  TwoViewGeometryConfig config = TwoViewGeometryConfig::kUndefined;
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Rigid3d cam2_from_cam1;
  FeatureMatches inlier_matches;

  // The same geometry seen from the other image (swapped roles).
  TwoViewGeometry Inverse() const;
};

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
  int64_t point_id = 0;                                   // index on the target
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();           // COLMAP pixels
  Eigen::Vector3d point_in_target = Eigen::Vector3d::Zero();  // metres
};

// portcal_target_detections: the outcome of target detection in an image.
struct TargetDetectionStatus {
  std::string target;  // e.g. "chessboard 10x7"
  bool found = false;
  int num_points = 0;
  std::string reason;  // why not, when not found
};

// portcal_marker_detections: one ArUco marker in an image.
struct MarkerDetection {
  std::string dictionary;  // e.g. DICT_4X4_50
  int marker_id = 0;
  std::array<Eigen::Vector2d, 4> corners;  // COLMAP pixels, OpenCV's order
};

// portcal_stage_log: one completed stage run.
struct StageLogEntry {
  int64_t run_id = 0;
  std::string stage;
  std::string options;     // the options as "name=value" lines
  std::string start_time;  // ISO 8601 UTC
  std::string end_time;
  std::string status;      // "succeeded"
  std::string counts;      // "name=value" lines
};

constexpr image_t kMaxNumImages = 2147483647;

// COLMAP's pair id: id1 * 2147483647 + id2 with id1 < id2.
image_pair_t ImagePairToPairId(image_t image_id1, image_t image_id2);
void PairIdToImagePair(image_pair_t pair_id, image_t* image_id1,
                       image_t* image_id2);
bool SwapImagePair(image_t image_id1, image_t image_id2);

}  // namespace portcal
