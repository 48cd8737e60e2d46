#include "pipelines/detection/detection_rows.h"

#include <sstream>

namespace portcal {

std::string TargetDescriptionText(const TargetDetectorOptions& options) {
  const auto metres = [](double value) {
    std::ostringstream out;
    out << value << " m";
    return out.str();
  };
  const MarkerBoardOptions& m = options.markers;
  return options.type == "chessboard"
             ? "chessboard " + std::to_string(options.chessboard.cols) + "x" +
                   std::to_string(options.chessboard.rows) + " inner corners, square " +
                   metres(options.square_size_m)
         : options.type == "aruco_grid"
             ? "aruco_grid " + std::to_string(m.markers_x) + "x" + std::to_string(m.markers_y) +
                   " " + m.dictionary + ", marker " + metres(m.marker_size_m) + ", separation " +
                   metres(m.marker_separation_m)
             : "charuco " + std::to_string(m.squares_x) + "x" + std::to_string(m.squares_y) +
                   " squares " + m.dictionary + ", square " + metres(options.square_size_m) +
                   ", marker " + metres(m.marker_size_m);
}

std::string DetectionStatusText(const TargetDetection& detection) {
  if (!detection.found) return detection.reason;
  std::string text = "found";
  if (detection.symmetric) text += " (symmetric board: order may be rotated by 180 deg)";
  if (!detection.note.empty()) text += "; " + detection.note;
  return text;
}

void WriteTargetDetection(Database* database, image_t image_id, const TargetDetection& detection,
                          const std::string& target) {
  std::vector<TargetObservation> observations;
  for (const BoardPoint& p : detection.points)
    observations.push_back({p.point_id, p.xy, p.point_in_target});
  database->WriteTargetObservations(image_id, observations);
  database->WriteMarkerDetections(image_id, detection.markers);
  TargetDetectionStatus status;
  status.target = target;
  status.found = detection.found;
  status.num_points = static_cast<int>(observations.size());
  status.reason = DetectionStatusText(detection);
  database->WriteTargetDetectionStatus(image_id, status);
}

}  // namespace portcal
