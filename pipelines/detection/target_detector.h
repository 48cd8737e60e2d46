// One detector for every planar target portcal knows (chessboard, ArUco
// grid, ChArUco): the target's points in one image, with the target's own
// coordinates, whatever its type. target_extractor runs it on every image
// (precise); live views run it quick on every frame and precise on the
// frames they keep.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "colmap_ext/feature/marker_detection.h"
#include "pipelines/markers/marker_board_detector.h"
#include "pipelines/target/chessboard_detector.h"

namespace portcal {

struct TargetDetectorOptions {
  std::string type = "chessboard";  // chessboard | aruco_grid | charuco
  double square_size_m = 0.02;      // chessboard and ChArUco squares, > 0
  ChessboardDetectionOptions chessboard;
  MarkerBoardOptions markers;  // its type and square size are this one's
  // false: tenths of a pixel at video rate; true: the ideal-pattern and
  // edge fits (hundredths). Sets the detectors' own `precise_fit`.
  bool precise_fit = true;
  void Check() const;  // throws OptionError naming --Target.*
};

struct TargetDetection {
  bool found = false;
  std::string reason;      // why not, when not found
  std::string note;        // found with points left out: how many and why
  bool symmetric = false;  // a chessboard that looks the same turned by 180 deg
  // point_id: chessboard r * cols + c; ArUco grid marker id * 4 + corner;
  // ChArUco corner id.
  std::vector<BoardPoint> points;
  std::vector<MarkerDetection> markers;  // marker boards: every board marker seen
};

TargetDetection DetectTarget(const cv::Mat& gray, const TargetDetectorOptions& options);

// Every point of the target (ids and positions as a detection gives them,
// xy unset): what a view of the whole target would see.
std::vector<BoardPoint> TargetLayout(const TargetDetectorOptions& options);

}  // namespace portcal
