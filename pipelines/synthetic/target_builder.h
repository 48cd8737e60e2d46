// Calibration targets for the renderer: their geometry (for ground truth and
// pose sampling) and what the renderer's rays hit.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/synthetic/scene.h"
#include "pipelines/synthetic/textures.h"

namespace portcal {

struct DotsOptions {
  uint64_t seed = 11;
  double r_min_m = 0.0015;
  double r_max_m = 0.009;
  double coverage = 0.5;  // fraction of the free face area covered, (0, 0.8]
  double gray_min = 20;
  double gray_max = 110;
  double edge_margin_m = 0.004;
};

struct TargetOptions {
  std::string type = "chessboard";  // chessboard | aruco_grid | charuco | target3d
  // chessboard: inner corners; charuco: squares (squares_x x squares_y).
  int cols = 10, rows = 7;
  int squares_x = 8, squares_y = 6;
  double square_size_m = 0.02;
  double margin_m = 0.015;
  // aruco_grid
  int markers_x = 5, markers_y = 4;
  double marker_size_m = 0.04;
  double marker_separation_m = 0.01;
  int first_marker = 0;
  std::string dictionary = "DICT_4X4_50";
  // target3d
  int num_faces = 2;
  double fold_angle_deg = 120;
  double face_width_m = 0.2, face_height_m = 0.25;
  std::vector<int> marker_ids;  // default 0 .. num_faces-1
  double target3d_marker_size_m = 0.06;
  int quiet_zone_modules = 1;
  DotsOptions dots;

  void Check() const;  // throws OptionError naming the field
};

struct BuiltTarget {
  TargetDescription description;
  std::unique_ptr<SceneObject> object;  // in the target frame
  // Points that must be visible for visibility "full" (all corners of the
  // print) and "markers" (marker corners), target frame.
  std::vector<Eigen::Vector3d> outline_points;
  std::vector<Eigen::Vector3d> marker_points;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d front_normal = -Eigen::Vector3d::UnitZ();  // towards the viewer
  std::vector<std::vector<Dot>> dots;                        // target3d: per face
};

BuiltTarget BuildTarget(const TargetOptions& options, const PrintLevels& levels);

// "face,x,y,radius,gray" lines of a target3d's dots (the dots_file).
std::string DotsCsv(const std::vector<std::vector<Dot>>& dots);

}  // namespace portcal
