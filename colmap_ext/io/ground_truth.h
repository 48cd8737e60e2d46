// Ground truth of a rendered image set: the "refrender-ground-truth" YAML
// format of ../shared/datasets/rendered (version 1), read and written by one
// implementation, so `portcal synthesize` output and the shared sets are
// interchangeable.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {

// One ArUco marker of a target: id and its 4 corners in the target frame
// (top-left, top-right, bottom-right, bottom-left of the printed marker, as
// cv::aruco::detectMarkers orders them).
struct TargetMarker {
  int id = 0;
  std::array<Eigen::Vector3d, 4> corners;
};

// A planar face of a 3-D target.
struct TargetFace {
  std::string name;
  Rigid3d target_from_face;
  Eigen::Vector2d extent_x = Eigen::Vector2d::Zero();  // [min, max] in the face frame
  Eigen::Vector2d extent_y = Eigen::Vector2d::Zero();
  int marker_id = 0;
  double marker_side = 0;    // m
  double marker_module = 0;  // m
  double quiet_zone = 0;     // m of white around the marker
  int num_dots = 0;
};

struct TargetDescription {
  // chessboard | aruco_grid | charuco | target3d | seabed
  std::string type;
  // Chessboard (and ChArUco squares): inner corners, square size, margin.
  int inner_corners_cols = 0;
  int inner_corners_rows = 0;
  double square_size = 0;
  double margin = 0;
  // ArUco grid / ChArUco / target3d markers.
  std::string aruco_dictionary;
  double marker_size = 0;
  double marker_separation = 0;  // aruco_grid
  int markers_x = 0, markers_y = 0;
  // The points whose pixels each image lists (chessboard and ChArUco inner
  // corners), index = point id.
  std::vector<Eigen::Vector3d> corners_3d;
  std::vector<TargetMarker> markers;
  // target3d
  std::string layout;
  double fold_angle_deg = 0;
  double face_width = 0, face_height = 0;
  std::vector<TargetFace> faces;
  std::string dots_file;
};

// What one camera saw in one frame.
struct ImageTruth {
  std::string file;  // relative to the set's directory
  Rigid3d cam_from_target;
  // Per target point (corners_3d order); nullopt where it does not project.
  std::vector<std::optional<Eigen::Vector2d>> corners_px;
  // Per target point: false if hidden by an occluder (written only when some
  // point is hidden).
  std::vector<bool> corners_visible;
  struct Marker {
    int id = 0;
    std::array<Eigen::Vector2d, 4> corners_px;
    bool fully_inside = true;
  };
  std::vector<Marker> markers;
};

struct FrameTruth {
  int frame = 0;
  ImageTruth cam1;
  std::optional<ImageTruth> cam2;  // stereo
};

struct StereoTruth {
  Rigid3d cam2_from_cam1;
  Camera camera2;
  std::optional<Housing> housing2;
  double baseline = 0;
  std::array<std::string, 2> image_dirs = {"images/cam1", "images/cam2"};
};

struct GroundTruth {
  std::string name;
  std::string description;
  int64_t seed = 0;
  Camera camera;
  std::optional<Housing> housing;
  std::optional<StereoTruth> stereo;
  TargetDescription target;
  std::vector<FrameTruth> images;
};

// Throws InputError naming the file (and key) on malformed content.
GroundTruth ReadGroundTruth(const std::filesystem::path& path);
// `extra_yaml`: further top-level blocks (render, clutter, pose_generation,
// survey...) already formatted as YAML, appended verbatim. Atomic write.
void WriteGroundTruth(const GroundTruth& truth, const std::filesystem::path& path,
                      const std::string& extra_yaml = "");

}  // namespace portcal
