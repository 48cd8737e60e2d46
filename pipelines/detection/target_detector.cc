#include "pipelines/detection/target_detector.h"

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {
namespace {

ChessboardDetectionOptions ChessboardOptions(const TargetDetectorOptions& options) {
  ChessboardDetectionOptions chessboard = options.chessboard;
  chessboard.precise_fit = options.precise_fit;
  return chessboard;
}

MarkerBoardOptions MarkerOptions(const TargetDetectorOptions& options) {
  MarkerBoardOptions board = options.markers;
  board.type = options.type;
  board.square_size_m = options.square_size_m;
  board.precise_fit = options.precise_fit;
  return board;
}

TargetDetection FromChessboard(const ChessboardDetection& d, const TargetDetectorOptions& options) {
  TargetDetection detection;
  detection.found = d.found;
  detection.reason = d.reason;
  detection.note = d.note;
  detection.symmetric = d.symmetric;
  if (!d.found) return detection;
  const int cols = options.chessboard.cols;
  for (size_t i = 0; i < d.corners.size(); ++i) {
    if (!d.corners[i]) continue;
    const int c = static_cast<int>(i) % cols, r = static_cast<int>(i) / cols;
    detection.points.push_back(
        {static_cast<int64_t>(i), *d.corners[i],
         Eigen::Vector3d(c * options.square_size_m, r * options.square_size_m, 0.0)});
  }
  return detection;
}

}  // namespace

void TargetDetectorOptions::Check() const {
  if (type != "chessboard" && type != "aruco_grid" && type != "charuco") {
    throw OptionError("--Target.type", type, "chessboard, aruco_grid or charuco");
  }
  if (!(square_size_m > 0)) throw OptionError("--Target.square_size", square_size_m, "> 0 m");
  // A board's squares and markers are millimetres to decimetres: a metre or
  // more is a size in millimetres given as metres.
  for (const auto& [option, size] : {std::pair("--Target.square_size", square_size_m),
                                     std::pair("--Target.marker_size", markers.marker_size_m)}) {
    if (size >= 1) {
      throw OptionError(
          option, FormatShortest(size),
          "metres (" + FormatShortest(size) + " mm is " + FormatShortest(size / 1000) + " m)");
    }
  }
  if (type == "chessboard") {
    ChessboardOptions(*this).Check();
  } else {
    MarkerOptions(*this).Check();
  }
}

TargetDetection DetectTarget(const cv::Mat& gray, const TargetDetectorOptions& options) {
  options.Check();
  if (options.type == "chessboard")
    return FromChessboard(DetectChessboard(gray, ChessboardOptions(options)), options);
  const MarkerBoardDetection d = DetectMarkerBoard(gray, MarkerOptions(options));
  TargetDetection detection;
  detection.found = d.found;
  detection.reason = d.reason;
  detection.note = d.note;
  detection.markers = d.markers;
  if (d.found) detection.points = d.points;
  return detection;
}

std::vector<BoardPoint> TargetLayout(const TargetDetectorOptions& options) {
  options.Check();
  if (options.type != "chessboard") return MarkerBoardLayout(MarkerOptions(options));
  std::vector<BoardPoint> points;
  for (int r = 0; r < options.chessboard.rows; ++r) {
    for (int c = 0; c < options.chessboard.cols; ++c) {
      points.push_back(
          {static_cast<int64_t>(r) * options.chessboard.cols + c, Eigen::Vector2d::Zero(),
           Eigen::Vector3d(c * options.square_size_m, r * options.square_size_m, 0.0)});
    }
  }
  return points;
}

}  // namespace portcal
