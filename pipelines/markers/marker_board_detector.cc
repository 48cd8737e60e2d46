#include "pipelines/markers/marker_board_detector.h"

#include <map>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include "colmap_ext/util/error.h"
#include "pipelines/markers/aruco.h"
#include "pipelines/markers/marker_edge_crossings.h"
#include "pipelines/markers/marker_edge_refinement.h"
#include "pipelines/target/coarse_level.h"

namespace portcal {

void MarkerBoardOptions::Check() const {
  if (type != "aruco_grid" && type != "charuco") {
    throw OptionError("--Target.type", type, "aruco_grid or charuco here");
  }
  CheckArucoDictionaryOption("--Target.dictionary", dictionary);
  if (type == "aruco_grid" && (markers_x < 1 || markers_y < 1)) {
    throw OptionError("--Target.markers_x/markers_y", markers_x, ">= 1 each");
  }
  if (type == "charuco" && (squares_x < 3 || squares_y < 3)) {
    throw OptionError("--Target.squares_x/squares_y", squares_x, ">= 3 each");
  }
  if (!(marker_size_m > 0)) throw OptionError("--Target.marker_size", marker_size_m, "> 0 m");
  if (type == "charuco" && !(square_size_m > marker_size_m)) {
    throw OptionError("--Target.square_size", square_size_m, "> marker_size");
  }
  if (min_points < 4) throw OptionError("--Target.min_points", min_points, ">= 4");
  if (coarse_max_image_size < 0) {
    throw OptionError("--Target.coarse_max_image_size", coarse_max_image_size, ">= 0");
  }
  refinement.Check();
}

namespace {

Eigen::Vector2d Colmap(const cv::Point2f& p) { return {p.x + 0.5, p.y + 0.5}; }

// The board the options describe; *charuco is set for a ChArUco board.
cv::Ptr<cv::aruco::Board> MakeBoard(const MarkerBoardOptions& options,
                                    const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                    cv::Ptr<cv::aruco::CharucoBoard>* charuco) {
  if (options.type == "aruco_grid") {
    return cv::aruco::GridBoard::create(
        options.markers_x, options.markers_y, static_cast<float>(options.marker_size_m),
        static_cast<float>(options.marker_separation_m), dictionary, options.first_marker);
  }
  *charuco = cv::aruco::CharucoBoard::create(options.squares_x, options.squares_y,
                                             static_cast<float>(options.square_size_m),
                                             static_cast<float>(options.marker_size_m), dictionary);
  return *charuco;
}

// The board's markers found in the image (OpenCV pixels), in detection order.
struct BoardMarkers {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  std::map<int, size_t> board_index;  // marker id -> index in the board
};

// The marker's corners (OpenCV pixels) refined at full resolution: false
// where its edges could not be located. The outline's edge curves give
// unbiased corners (OpenCV's contour corners sit ~0.6 px inside, and pixels
// off on foreshortened markers). Precise ArUco grids fit the edges to the
// pixels; a ChArUco board's markers give no board points, so the quicker
// crossings (marker_edge_crossings.h) do for their detections, as for
// quick views.
bool RefineMarker(const cv::Mat& gray, const MarkerBoardOptions& options, int bits_per_side,
                  std::vector<cv::Point2f>* corners) {
  std::array<cv::Point2d, 4> quad;
  for (int k = 0; k < 4; ++k) quad[k] = cv::Point2d((*corners)[k].x, (*corners)[k].y);
  MarkerEdgeRefinementOptions edge_options;
  edge_options.bits_per_side = bits_per_side;
  const bool fitted = options.type == "aruco_grid" && options.precise_fit
                          ? RefineMarkerCorners(gray, edge_options, &quad)
                          : RefineMarkerCornersByCrossings(gray, edge_options, &quad);
  if (!fitted) return false;
  for (int k = 0; k < 4; ++k)
    (*corners)[k] = cv::Point2f(static_cast<float>(quad[k].x), static_cast<float>(quad[k].y));
  return true;
}

// OpenCV's marker detection: at full resolution with its contour fit, or
// (quick) on the coarse level without one, the corners then brought back
// to full-resolution pixels.
void DetectMarkersOnLevel(const cv::Mat& gray, const MarkerBoardOptions& options,
                          const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                          const cv::Ptr<cv::aruco::Board>& board,
                          std::vector<std::vector<cv::Point2f>>* corners, std::vector<int>* ids) {
  const auto [scale, level] = options.precise_fit
                                  ? std::pair<double, cv::Mat>(1.0, gray)
                                  : CoarseLevel(gray, options.coarse_max_image_size);
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  // Line fits to the contour: sub-pixel without cornerSubPix's habit of
  // jumping to a neighbouring marker. Quick: the crossings start from the
  // coarse corners anyway.
  parameters->cornerRefinementMethod =
      options.precise_fit ? cv::aruco::CORNER_REFINE_CONTOUR : cv::aruco::CORNER_REFINE_NONE;
  std::vector<std::vector<cv::Point2f>> rejected;
  cv::aruco::detectMarkers(level, dictionary, *corners, *ids, parameters, rejected);
  if (!ids->empty()) cv::aruco::refineDetectedMarkers(level, board, *corners, *ids, rejected);
  if (scale == 1.0) return;
  for (auto& marker : *corners) {
    for (cv::Point2f& p : marker) {
      p = cv::Point2f(static_cast<float>((p.x + 0.5) / scale - 0.5),
                      static_cast<float>((p.y + 0.5) / scale - 0.5));
    }
  }
}

BoardMarkers DetectBoardMarkers(const cv::Mat& gray, const MarkerBoardOptions& options,
                                const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                const cv::Ptr<cv::aruco::Board>& board,
                                MarkerBoardDetection* detection) {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  DetectMarkersOnLevel(gray, options, dictionary, board, &corners, &ids);
  BoardMarkers found;
  for (size_t i = 0; i < board->ids.size(); ++i) found.board_index[board->ids[i]] = i;
  for (size_t m = 0; m < ids.size(); ++m) {
    const auto it = found.board_index.find(ids[m]);
    if (it == found.board_index.end()) continue;  // a marker of another target
    // OpenCV interpolates a ChArUco board's corners from its markers' own
    // corners: with the crossings' corners instead, the rendered boards'
    // worst corner went from 0.096 to 0.198 px (docs/benchmarks_target_detection.md).
    found.corners.push_back(corners[m]);
    const bool edges_fitted = RefineMarker(gray, options, dictionary->markerSize, &corners[m]);
    found.ids.push_back(ids[m]);
    MarkerDetection marker;
    marker.dictionary = options.dictionary;
    marker.marker_id = ids[m];
    for (int k = 0; k < 4; ++k) marker.corners[k] = Colmap(corners[m][k]);
    detection->markers.push_back(marker);
    if (options.type != "aruco_grid") continue;
    if (!edges_fitted) {
      ++detection->num_markers_unfitted;  // its corners are pixels off: left out
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      const cv::Point3f& p = board->objPoints[it->second][k];
      detection->points.push_back({static_cast<int64_t>(ids[m]) * 4 + k, Colmap(corners[m][k]),
                                   Eigen::Vector3d(p.x, p.y, p.z)});
    }
  }
  return found;
}

// The board-to-image homography of the markers' contour corners (empty
// with fewer than 4): the local board axes in the image, for the corner
// refinement's window and the edges' initial directions.
cv::Mat MarkersHomography(const BoardMarkers& markers, const cv::aruco::Board& board) {
  std::vector<cv::Point2f> object_xy, image_xy;
  for (size_t m = 0; m < markers.ids.size(); ++m) {
    const size_t index = markers.board_index.at(markers.ids[m]);
    for (int k = 0; k < 4; ++k) {
      object_xy.emplace_back(board.objPoints[index][k].x, board.objPoints[index][k].y);
      image_xy.push_back(markers.corners[m][k]);
    }
  }
  return object_xy.size() >= 4 ? cv::findHomography(object_xy, image_xy) : cv::Mat();
}

// The chessboard corners between the markers, interpolated by OpenCV and
// refined on the two-edge pattern.
void AddCharucoCorners(const cv::Mat& gray, const MarkerBoardOptions& options,
                       const BoardMarkers& markers, const cv::Ptr<cv::aruco::CharucoBoard>& charuco,
                       MarkerBoardDetection* detection) {
  std::vector<cv::Point2f> charuco_corners;
  std::vector<int> charuco_ids;
  cv::aruco::interpolateCornersCharuco(markers.corners, markers.ids, gray, charuco, charuco_corners,
                                       charuco_ids);
  if (!options.precise_fit && !charuco_corners.empty()) {
    cv::cornerSubPix(gray, charuco_corners, cv::Size(2, 2), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10, 0.01));
  }
  const cv::Mat homography = MarkersHomography(markers, *charuco);
  const auto to_image = [&](double x, double y) {
    const cv::Mat h = homography;
    const double w = h.at<double>(2, 0) * x + h.at<double>(2, 1) * y + h.at<double>(2, 2);
    return Eigen::Vector2d(
        (h.at<double>(0, 0) * x + h.at<double>(0, 1) * y + h.at<double>(0, 2)) / w,
        (h.at<double>(1, 0) * x + h.at<double>(1, 1) * y + h.at<double>(1, 2)) / w);
  };
  for (size_t i = 0; i < charuco_ids.size(); ++i) {
    const cv::Point3f& p = charuco->chessboardCorners[charuco_ids[i]];
    Eigen::Vector2d xy = Colmap(charuco_corners[i]);
    if (!homography.empty() && options.precise_fit) {
      const double s = options.square_size_m;
      const Eigen::Vector2d dx = to_image(p.x + s, p.y) - to_image(p.x, p.y);
      const Eigen::Vector2d dy = to_image(p.x, p.y + s) - to_image(p.x, p.y);
      // Stay inside the white margin around the neighbouring markers:
      // their modules are not part of the corner's two-edge pattern.
      const double margin =
          0.5 * (options.square_size_m - options.marker_size_m) / options.square_size_m;
      const double fraction = std::min(options.refinement.window_fraction, 0.9 * margin);
      const double half =
          std::clamp(fraction * std::min(dx.norm(), dy.norm()), options.refinement.min_window_px,
                     options.refinement.max_window_px);
      const auto refined = RefineCorner(gray, xy, half, std::atan2(dx.x(), -dx.y()),
                                        std::atan2(dy.x(), -dy.y()), options.refinement);
      if (!refined) {  // no clean corner there
        ++detection->num_corners_unrefined;
        continue;
      }
      xy = refined->xy;
    }
    detection->points.push_back({charuco_ids[i], xy, Eigen::Vector3d(p.x, p.y, p.z)});
  }
}

}  // namespace

MarkerBoardDetection DetectMarkerBoard(const cv::Mat& gray, const MarkerBoardOptions& options) {
  options.Check();
  MarkerBoardDetection detection;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = ArucoDictionaryByName(options.dictionary);
  cv::Ptr<cv::aruco::CharucoBoard> charuco;
  const cv::Ptr<cv::aruco::Board> board = MakeBoard(options, dictionary, &charuco);
  const BoardMarkers markers = DetectBoardMarkers(gray, options, dictionary, board, &detection);
  if (options.type == "charuco" && !markers.ids.empty())
    AddCharucoCorners(gray, options, markers, charuco, &detection);
  if (static_cast<int>(detection.points.size()) < options.min_points) {
    detection.reason = "only " + std::to_string(detection.points.size()) + " board points (" +
                       std::to_string(markers.ids.size()) + " of the board's markers) found";
    return detection;
  }
  detection.found = true;
  if (detection.num_markers_unfitted > 0) {
    const int found = static_cast<int>(markers.ids.size());
    const int unfitted = detection.num_markers_unfitted;
    detection.note =
        std::to_string(4 * unfitted) + " of " + std::to_string(4 * found) +
        " marker corners left out (" + std::to_string(unfitted) +
        (unfitted == 1 ? " marker" : " markers") +
        (unfitted == 1 ? " too foreshortened, cut or blurred for its edges to be fitted)"
                       : " too foreshortened, cut or blurred for their edges to be fitted)");
  } else if (detection.num_corners_unrefined > 0) {
    detection.note = std::to_string(detection.num_corners_unrefined) + " of " +
                     std::to_string(detection.num_corners_unrefined + detection.points.size()) +
                     " corners left out (no clean corner)";
  }
  return detection;
}

std::vector<BoardPoint> MarkerBoardLayout(const MarkerBoardOptions& options) {
  options.Check();
  cv::Ptr<cv::aruco::CharucoBoard> charuco;
  const cv::Ptr<cv::aruco::Board> board =
      MakeBoard(options, ArucoDictionaryByName(options.dictionary), &charuco);
  std::vector<BoardPoint> points;
  if (charuco) {
    for (size_t i = 0; i < charuco->chessboardCorners.size(); ++i) {
      const cv::Point3f& p = charuco->chessboardCorners[i];
      points.push_back(
          {static_cast<int64_t>(i), Eigen::Vector2d::Zero(), Eigen::Vector3d(p.x, p.y, p.z)});
    }
    return points;
  }
  for (size_t m = 0; m < board->ids.size(); ++m) {
    for (int k = 0; k < 4; ++k) {
      const cv::Point3f& p = board->objPoints[m][static_cast<size_t>(k)];
      points.push_back({static_cast<int64_t>(board->ids[m]) * 4 + k, Eigen::Vector2d::Zero(),
                        Eigen::Vector3d(p.x, p.y, p.z)});
    }
  }
  return points;
}

}  // namespace portcal
