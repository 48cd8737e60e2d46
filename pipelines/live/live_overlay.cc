#include "pipelines/live/live_overlay.h"

#include <functional>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pipelines/guidance/pose_preview.h"
#include "pipelines/report/picture.h"

namespace portcal {
namespace {

double ScaleFor(const cv::Size& size, int max_width) {
  return size.width > max_width && max_width > 0 ? static_cast<double>(max_width) / size.width
                                                 : 1.0;
}

cv::Mat ScaledBgr(const cv::Mat& gray, double scale) {
  cv::Mat bgr;
  if (gray.empty()) return cv::Mat(360, 640, CV_8UC3, cv::Scalar(40, 40, 40));
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  if (scale != 1.0) cv::resize(bgr, bgr, cv::Size(), scale, scale, cv::INTER_AREA);
  return bgr;
}

void Caption(const std::string& text, int line, cv::Mat* bgr) {
  const double size = std::max(0.4, bgr->cols / 1100.0);
  const cv::Point at(10, static_cast<int>((line + 1) * 26 * size / 0.6));
  cv::putText(*bgr, text, at, cv::FONT_HERSHEY_SIMPLEX, size, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
  cv::putText(*bgr, text, at, cv::FONT_HERSHEY_SIMPLEX, size, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

cv::Mat DrawOneOverlay(const LiveSnapshot& snapshot, const TargetShape& target, int max_width) {
  const double scale = ScaleFor(snapshot.frame.size(), max_width);
  cv::Mat bgr = ScaledBgr(snapshot.frame, scale);
  const cv::Scalar color = snapshot.hold.still        ? cv::Scalar(0, 220, 0)
                           : snapshot.hold.held_s > 0 ? cv::Scalar(0, 220, 255)
                                                      : cv::Scalar(0, 0, 255);
  for (const auto& [id, pixel] : snapshot.corners) {
    cv::circle(
        bgr,
        cv::Point(cvRound((pixel.x() - 0.5) * scale * 16), cvRound((pixel.y() - 0.5) * scale * 16)),
        4 * 16, color, 1, cv::LINE_AA, 4);
  }
  const LiveEstimate* estimate = snapshot.estimate.get();
  if (estimate && estimate->next) {
    const std::vector<cv::Point2f> outline =
        TargetOutlinePixels(estimate->camera, target, estimate->next->cam_from_target);
    std::vector<cv::Point> polygon;
    for (const cv::Point2f& p : outline)
      polygon.emplace_back(cvRound(p.x * scale * 16), cvRound(p.y * scale * 16));
    if (!polygon.empty())
      cv::polylines(bgr, polygon, true, cv::Scalar(0, 140, 255), 2, cv::LINE_AA, 4);
  }
  std::ostringstream line;
  line << std::fixed << std::setprecision(1) << snapshot.fps << " fps  ";
  if (!snapshot.target_seen) {
    line << "no target";
  } else {
    line << snapshot.corners.size() << " corners, held " << snapshot.hold.held_s << " s";
  }
  line << "  " << snapshot.kept.size() << " kept";
  Caption(line.str(), 0, &bgr);
  if (snapshot.to_suggestion && estimate && estimate->next) {
    // Angles and distances only once the camera is estimated: before, the
    // pose of the frame rests on a guessed focal length, and it said "59
    // deg, 41 cm" while the board filled the outline.
    std::ostringstream away;
    away << std::fixed << std::setprecision(0)
         << "to the suggested pose: " << snapshot.to_suggestion->outline_px << " px";
    if (estimate->solved) {
      away << ", " << snapshot.to_suggestion->rotation_deg << " deg, "
           << 100 * snapshot.to_suggestion->translation_m << " cm";
    }
    Caption(away.str(), 1, &bgr);
  }
  return bgr;
}

}  // namespace

double CoverageFraction(const LiveSnapshot& snapshot) {
  if (snapshot.frame.empty()) return 0;
  const cv::Size cells(16, 9);
  cv::Mat occupied = cv::Mat::zeros(cells, CV_8U);
  for (const KeptView& kept : snapshot.kept) {
    for (const Eigen::Vector2d& pixel : kept.view.pixels) {
      const int x = static_cast<int>(pixel.x() * cells.width / snapshot.frame.cols);
      const int y = static_cast<int>(pixel.y() * cells.height / snapshot.frame.rows);
      if (x >= 0 && y >= 0 && x < cells.width && y < cells.height) occupied.at<uint8_t>(y, x) = 1;
    }
  }
  return cv::countNonZero(occupied) / static_cast<double>(cells.area());
}

namespace {

cv::Mat DrawOneCoverage(const LiveSnapshot& snapshot, int max_width) {
  const double scale = ScaleFor(snapshot.frame.size(), max_width);
  cv::Mat bgr = ScaledBgr(snapshot.frame, scale) * 0.4;
  cv::Mat counts = cv::Mat::zeros(bgr.size(), CV_32F);
  for (const KeptView& kept : snapshot.kept) {
    for (const Eigen::Vector2d& pixel : kept.view.pixels) {
      const int x = static_cast<int>(pixel.x() * scale), y = static_cast<int>(pixel.y() * scale);
      if (x >= 0 && y >= 0 && x < counts.cols && y < counts.rows) counts.at<float>(y, x) += 1;
    }
  }
  const double sigma = std::max(4.0, bgr.cols / 40.0);
  cv::GaussianBlur(counts, counts, cv::Size(), sigma);
  double peak = 0;
  cv::minMaxLoc(counts, nullptr, &peak);
  if (peak <= 0) return bgr;
  cv::Mat level;
  counts.convertTo(level, CV_8U, 255.0 / peak);
  cv::Mat heat;
  cv::applyColorMap(level, heat, cv::COLORMAP_TURBO);
  cv::Mat mask = level > 8;
  cv::addWeighted(bgr, 0.35, heat, 0.65, 0, heat);
  heat.copyTo(bgr, mask);
  return bgr;
}

cv::Mat DrawOneUncertainty(const LiveSnapshot& snapshot, int max_width) {
  const double scale = ScaleFor(snapshot.frame.size(), max_width);
  const cv::Size size = snapshot.frame.empty() ? cv::Size(640, 360)
                                               : cv::Size(cvRound(snapshot.frame.cols * scale),
                                                          cvRound(snapshot.frame.rows * scale));
  cv::Mat bgr(size, CV_8UC3, cv::Scalar(50, 50, 50));
  const LiveEstimate* estimate = snapshot.estimate.get();
  if (!estimate || !estimate->uncertainty.determined) {
    Caption(estimate ? "not yet determined: " + estimate->status : "no estimate yet", 0, &bgr);
    return bgr;
  }
  // The report's heat map with a colour bar (numbers in 32 x 24 cells were
  // unreadable on the page), the goal as a white iso-line.
  HeatMapStyle style;
  std::ostringstream title;
  title << std::setprecision(3) << "expected projection uncertainty: mean "
        << estimate->uncertainty.mean_px << " px, max " << estimate->uncertainty.max_px << " px";
  style.title = title.str();
  style.unit = "px";
  if (snapshot.goal.target_px > 0) style.contour_levels = {snapshot.goal.target_px};
  const int width = snapshot.frame.empty() ? size.width : snapshot.frame.cols;
  const int height = snapshot.frame.empty() ? size.height : snapshot.frame.rows;
  cv::Mat picture = HeatMapPicture(estimate->uncertainty.map_px, width, height, style);
  if (picture.cols > max_width && max_width > 0) {
    cv::resize(picture, picture,
               cv::Size(max_width, std::max(1, picture.rows * max_width / picture.cols)), 0, 0,
               cv::INTER_AREA);
  }
  return picture;
}

// Camera 2 of a rig as camera 1's fields (no distance to the suggestion:
// that line is camera 1's).
LiveSnapshot SecondCamera(const LiveSnapshot& snapshot) {
  LiveSnapshot second = snapshot;
  second.frame = snapshot.frame2;
  second.corners = snapshot.corners2;
  second.to_suggestion.reset();
  for (KeptView& kept : second.kept) {
    kept.view = kept.view2;
    kept.corners = kept.corners2;
  }
  second.estimate = snapshot.estimate ? snapshot.estimate->camera2 : nullptr;
  return second;
}

// One camera's picture, or a rig's two side by side (each half as wide).
cv::Mat PerCamera(const LiveSnapshot& snapshot, int max_width,
                  const std::function<cv::Mat(const LiveSnapshot&, int)>& draw) {
  if (snapshot.frame2.empty()) return draw(snapshot, max_width);
  cv::Mat first = draw(snapshot, max_width / 2),
          second = draw(SecondCamera(snapshot), max_width / 2);
  if (second.rows != first.rows) {
    cv::resize(second, second,
               cv::Size(second.cols * first.rows / std::max(1, second.rows), first.rows));
  }
  cv::Mat joined;
  cv::hconcat(first, second, joined);
  return joined;
}

}  // namespace

cv::Mat DrawLiveOverlay(const LiveSnapshot& snapshot, const TargetShape& target, int max_width) {
  return PerCamera(snapshot, max_width, [&target](const LiveSnapshot& s, int width) {
    return DrawOneOverlay(s, target, width);
  });
}

cv::Mat DrawCoverage(const LiveSnapshot& snapshot, int max_width) {
  return PerCamera(snapshot, max_width, DrawOneCoverage);
}

cv::Mat DrawUncertainty(const LiveSnapshot& snapshot, int max_width) {
  return PerCamera(snapshot, max_width, DrawOneUncertainty);
}

}  // namespace portcal
