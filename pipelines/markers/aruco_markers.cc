#include "pipelines/markers/aruco_markers.h"

#include <opencv2/aruco.hpp>

#include "pipelines/markers/aruco.h"
#include "pipelines/markers/marker_edge_crossings.h"

namespace portcal {

std::vector<MarkerDetection> DetectArucoMarkers(const cv::Mat& gray,
                                                const std::string& dictionary) {
  const cv::Ptr<cv::aruco::Dictionary> dict = ArucoDictionaryByName(dictionary);
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dict, corners, ids, parameters);
  std::vector<MarkerDetection> markers;
  MarkerEdgeRefinementOptions refinement;
  refinement.bits_per_side = dict->markerSize;
  for (size_t m = 0; m < ids.size(); ++m) {
    MarkerDetection detection;
    detection.dictionary = dictionary;
    detection.marker_id = ids[m];
    std::array<cv::Point2d, 4> quad;
    for (int c = 0; c < 4; ++c) quad[c] = cv::Point2d(corners[m][c].x, corners[m][c].y);
    // Edge-line corners where the edges allow (see marker_edge_crossings.h).
    RefineMarkerCornersByCrossings(gray, refinement, &quad);
    for (int c = 0; c < 4; ++c)
      detection.corners[c] = Eigen::Vector2d(quad[c].x + 0.5, quad[c].y + 0.5);
    markers.push_back(detection);
  }
  return markers;
}

bool InsideEnlargedQuad(const std::array<Eigen::Vector2d, 4>& quad, double factor,
                        const Eigen::Vector2d& xy) {
  const Eigen::Vector2d centroid = 0.25 * (quad[0] + quad[1] + quad[2] + quad[3]);
  // Inside a convex polygon: the same side of every edge. Scaling the quad
  // about the centroid is scaling the point by 1/factor instead.
  const Eigen::Vector2d p = centroid + (xy - centroid) / factor;
  int sign = 0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d e = quad[(i + 1) % 4] - quad[i];
    const Eigen::Vector2d d = p - quad[i];
    const double cross = e.x() * d.y() - e.y() * d.x();
    const int s = cross > 0 ? 1 : (cross < 0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

}  // namespace portcal
