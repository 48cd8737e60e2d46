#include "pipelines/markers/marker_board_detector.h"

#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <map>

#include "colmap_ext/util/error.h"
#include "pipelines/markers/aruco.h"
#include "pipelines/markers/marker_edge_refinement.h"

namespace portcal {

void MarkerBoardOptions::Check() const {
  if (type != "aruco_grid" && type != "charuco") {
    throw OptionError("--Target.type", type, "aruco_grid or charuco here");
  }
  ArucoDictionaryByName(dictionary);
  if (type == "aruco_grid" && (markers_x < 1 || markers_y < 1)) {
    throw OptionError("--Target.markers_x/markers_y", std::to_string(markers_x), ">= 1 each");
  }
  if (type == "charuco" && (squares_x < 3 || squares_y < 3)) {
    throw OptionError("--Target.squares_x/squares_y", std::to_string(squares_x), ">= 3 each");
  }
  if (!(marker_size_m > 0)) throw OptionError("--Target.marker_size", std::to_string(marker_size_m), "> 0 m");
  if (type == "charuco" && !(square_size_m > marker_size_m)) {
    throw OptionError("--Target.square_size", std::to_string(square_size_m), "> marker_size");
  }
  if (min_points < 4) throw OptionError("--Target.min_points", std::to_string(min_points), ">= 4");
  refinement.Check();
}

namespace {

Eigen::Vector2d Colmap(const cv::Point2f& p) { return {p.x + 0.5, p.y + 0.5}; }

}  // namespace

MarkerBoardDetection DetectMarkerBoard(const cv::Mat& gray, const MarkerBoardOptions& options) {
  options.Check();
  MarkerBoardDetection detection;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = ArucoDictionaryByName(options.dictionary);
  cv::Ptr<cv::aruco::Board> board;
  cv::Ptr<cv::aruco::CharucoBoard> charuco;
  if (options.type == "aruco_grid") {
    board = cv::aruco::GridBoard::create(options.markers_x, options.markers_y,
                                         static_cast<float>(options.marker_size_m),
                                         static_cast<float>(options.marker_separation_m), dictionary,
                                         options.first_marker);
  } else {
    charuco = cv::aruco::CharucoBoard::create(options.squares_x, options.squares_y,
                                              static_cast<float>(options.square_size_m),
                                              static_cast<float>(options.marker_size_m), dictionary);
    board = charuco;
  }
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  // Line fits to the contour: sub-pixel without cornerSubPix's habit of
  // jumping to a neighbouring marker.
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_CONTOUR;
  std::vector<std::vector<cv::Point2f>> corners, rejected;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dictionary, corners, ids, parameters, rejected);
  if (!ids.empty()) cv::aruco::refineDetectedMarkers(gray, board, corners, ids, rejected);
  std::map<int, size_t> board_index;
  for (size_t i = 0; i < board->ids.size(); ++i) board_index[board->ids[i]] = i;
  std::vector<std::vector<cv::Point2f>> board_corners;
  std::vector<int> board_ids;
  for (size_t m = 0; m < ids.size(); ++m) {
    const auto it = board_index.find(ids[m]);
    if (it == board_index.end()) continue;  // a marker of another target
    board_corners.push_back(corners[m]);
    board_ids.push_back(ids[m]);
    // The outline's edge curves give unbiased corners (OpenCV's contour
    // corners sit ~0.6 px inside); where the edges are unusable the contour
    // corners stay.
    std::array<cv::Point2d, 4> quad;
    for (int k = 0; k < 4; ++k) quad[k] = cv::Point2d(corners[m][k].x, corners[m][k].y);
    MarkerEdgeRefinementOptions edge_options;
    edge_options.bits_per_side = dictionary->markerSize;
    if (RefineMarkerCorners(gray, edge_options, &quad)) {
      for (int k = 0; k < 4; ++k) corners[m][k] = cv::Point2f(static_cast<float>(quad[k].x), static_cast<float>(quad[k].y));
    }
    MarkerDetection marker;
    marker.dictionary = options.dictionary;
    marker.marker_id = ids[m];
    for (int k = 0; k < 4; ++k) marker.corners[k] = Colmap(corners[m][k]);
    detection.markers.push_back(marker);
    if (options.type == "aruco_grid") {
      for (int k = 0; k < 4; ++k) {
        const cv::Point3f& p = board->objPoints[it->second][k];
        detection.points.push_back({static_cast<int64_t>(ids[m]) * 4 + k, Colmap(corners[m][k]),
                                    Eigen::Vector3d(p.x, p.y, p.z)});
      }
    }
  }
  if (options.type == "charuco" && !board_ids.empty()) {
    std::vector<cv::Point2f> charuco_corners;
    std::vector<int> charuco_ids;
    cv::aruco::interpolateCornersCharuco(board_corners, board_ids, gray, charuco, charuco_corners, charuco_ids);
    // Local board axes in the image from the markers' homography, for the
    // refinement window and the edges' initial directions.
    std::vector<cv::Point2f> object_xy, image_xy;
    for (size_t m = 0; m < board_ids.size(); ++m) {
      const size_t index = board_index[board_ids[m]];
      for (int k = 0; k < 4; ++k) {
        object_xy.emplace_back(board->objPoints[index][k].x, board->objPoints[index][k].y);
        image_xy.push_back(board_corners[m][k]);
      }
    }
    const cv::Mat homography = object_xy.size() >= 4 ? cv::findHomography(object_xy, image_xy) : cv::Mat();
    const auto to_image = [&](double x, double y) {
      const cv::Mat h = homography;
      const double w = h.at<double>(2, 0) * x + h.at<double>(2, 1) * y + h.at<double>(2, 2);
      return Eigen::Vector2d((h.at<double>(0, 0) * x + h.at<double>(0, 1) * y + h.at<double>(0, 2)) / w,
                             (h.at<double>(1, 0) * x + h.at<double>(1, 1) * y + h.at<double>(1, 2)) / w);
    };
    for (size_t i = 0; i < charuco_ids.size(); ++i) {
      const cv::Point3f& p = charuco->chessboardCorners[charuco_ids[i]];
      Eigen::Vector2d xy = Colmap(charuco_corners[i]);
      if (!homography.empty()) {
        const double s = options.square_size_m;
        const Eigen::Vector2d dx = to_image(p.x + s, p.y) - to_image(p.x, p.y);
        const Eigen::Vector2d dy = to_image(p.x, p.y + s) - to_image(p.x, p.y);
        // Stay inside the white margin around the neighbouring markers:
        // their modules are not part of the corner's two-edge pattern.
        const double margin = 0.5 * (options.square_size_m - options.marker_size_m) / options.square_size_m;
        const double fraction = std::min(options.refinement.window_fraction, 0.9 * margin);
        const double half = std::clamp(fraction * std::min(dx.norm(), dy.norm()),
                                       options.refinement.min_window_px, options.refinement.max_window_px);
        const auto refined = RefineCorner(gray, xy, half, std::atan2(dx.x(), -dx.y()),
                                          std::atan2(dy.x(), -dy.y()), options.refinement);
        if (!refined) continue;  // no clean corner there
        xy = refined->xy;
      }
      detection.points.push_back({charuco_ids[i], xy, Eigen::Vector3d(p.x, p.y, p.z)});
    }
  }
  if (static_cast<int>(detection.points.size()) < options.min_points) {
    detection.reason = "only " + std::to_string(detection.points.size()) + " board points (" +
                       std::to_string(board_ids.size()) + " of the board's markers) found";
    return detection;
  }
  detection.found = true;
  return detection;
}

}  // namespace portcal
