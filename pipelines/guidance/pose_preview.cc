#include "pipelines/guidance/pose_preview.h"

#include <opencv2/imgproc.hpp>

namespace portcal {

std::vector<cv::Point2f> TargetOutlinePixels(const HousedCamera& camera, const TargetShape& target,
                                             const Rigid3d& cam_from_target) {
  std::vector<cv::Point2f> polygon;
  const int steps = 24;  // per edge: enough to show the curvature of distortion
  const size_t n = target.outline.size();
  for (size_t e = 0; e < n; ++e) {
    const Eigen::Vector3d& a = target.outline[e];
    const Eigen::Vector3d& b = target.outline[(e + 1) % n];
    for (int k = 0; k < steps; ++k) {
      const auto pixel =
          camera.Project(cam_from_target * (a + (b - a) * (static_cast<double>(k) / steps)));
      if (!pixel) return {};
      polygon.emplace_back(static_cast<float>(pixel->x() - 0.5),
                           static_cast<float>(pixel->y() - 0.5));
    }
  }
  return polygon;
}

void DrawTargetAt(const HousedCamera& camera, const TargetShape& target,
                  const Rigid3d& cam_from_target, const cv::Scalar& color, bool with_points,
                  cv::Mat* bgr) {
  const std::vector<cv::Point2f> outline = TargetOutlinePixels(camera, target, cam_from_target);
  std::vector<cv::Point> polygon;
  // Sub-pixel lines: 4 fractional bits.
  for (const cv::Point2f& p : outline) polygon.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
  if (!polygon.empty()) cv::polylines(*bgr, polygon, true, color, 2, cv::LINE_AA, 4);
  if (!with_points) return;
  for (const Eigen::Vector3d& point : target.points) {
    const auto pixel = camera.Project(cam_from_target * point);
    if (!pixel) continue;
    cv::circle(*bgr, cv::Point(cvRound((pixel->x() - 0.5) * 16), cvRound((pixel->y() - 0.5) * 16)),
               2 * 16, color, 1, cv::LINE_AA, 4);
  }
}

cv::Mat PosePreview(const HousedCamera& camera, const TargetShape& target,
                    const Rigid3d& cam_from_target, const std::string& caption) {
  cv::Mat bgr(static_cast<int>(camera.camera.height), static_cast<int>(camera.camera.width),
              CV_8UC3, cv::Scalar(60, 60, 60));
  const std::vector<cv::Point2f> outline = TargetOutlinePixels(camera, target, cam_from_target);
  std::vector<cv::Point> polygon(outline.begin(), outline.end());
  if (!polygon.empty())
    cv::fillPoly(bgr, std::vector<std::vector<cv::Point>>{polygon}, cv::Scalar(230, 230, 230));
  DrawTargetAt(camera, target, cam_from_target, cv::Scalar(0, 140, 255), true, &bgr);
  const double scale = std::max(0.5, bgr.cols / 1400.0);
  cv::putText(bgr, caption, cv::Point(12, static_cast<int>(30 * scale)), cv::FONT_HERSHEY_SIMPLEX,
              0.7 * scale, cv::Scalar(255, 255, 255), std::max(1, static_cast<int>(2 * scale)),
              cv::LINE_AA);
  return bgr;
}

}  // namespace portcal
