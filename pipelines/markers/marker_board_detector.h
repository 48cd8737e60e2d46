// ArUco grid boards and ChArUco boards (OpenCV 4.6 contrib's layouts):
// partial views allowed. ArUco grid: the 4 corners of every detected board
// marker whose outline's edges could be fitted (marker_edge_refinement.h).
// ChArUco: the chessboard corners
// OpenCV interpolates from the markers, refined by portcal's ideal-pattern
// fit.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "colmap_ext/feature/marker_detection.h"
#include "pipelines/target/corner_refinement.h"

namespace portcal {

struct MarkerBoardOptions {
  std::string type = "aruco_grid";  // aruco_grid | charuco
  std::string dictionary = "DICT_4X4_50";
  // aruco_grid
  int markers_x = 5, markers_y = 4;
  double marker_size_m = 0.04;
  double marker_separation_m = 0.01;
  int first_marker = 0;
  // charuco (marker_size_m is the markers' side inside the squares)
  int squares_x = 8, squares_y = 6;
  double square_size_m = 0.03;
  int min_points = 6;  // fewer: the view is refused
  // false, for live views: the markers are found on the image halved to at
  // most `coarse_max_image_size` pixels on its longer side, ArUco grid
  // corners come from the edges' half-level crossings
  // (marker_edge_crossings.h) and ChArUco corners as OpenCV interpolates
  // them (cornerSubPix): tenths of a pixel at video rate. true: markers at
  // full resolution, the edges and corners fitted to the pixels
  // (hundredths of a pixel, several times slower).
  bool precise_fit = true;
  int coarse_max_image_size = 1000;  // quick mode only; 0: full resolution
  CornerRefinementOptions refinement;
  void Check() const;  // throws OptionError naming --Target.*
};

struct BoardPoint {
  int64_t point_id = 0;             // aruco_grid: marker id * 4 + corner; charuco: corner id
  Eigen::Vector2d xy;               // COLMAP pixels
  Eigen::Vector3d point_in_target;  // metres, OpenCV's board frame
};

struct MarkerBoardDetection {
  bool found = false;
  std::string reason;
  std::vector<BoardPoint> points;
  std::vector<MarkerDetection> markers;  // every board marker seen
  // Seen but left out: ArUco grid markers whose edges could not be fitted;
  // ChArUco corners the ideal-pattern fit refused. Why, for the status.
  int num_markers_unfitted = 0;
  int num_corners_unrefined = 0;
  std::string note;
};

MarkerBoardDetection DetectMarkerBoard(const cv::Mat& gray, const MarkerBoardOptions& options);

// Every point the board has, with the ids and positions a detection gives
// (xy unset): what a view of the whole board would see.
std::vector<BoardPoint> MarkerBoardLayout(const MarkerBoardOptions& options);

}  // namespace portcal
