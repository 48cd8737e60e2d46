// A video that behaves like a person holding a board before a camera, made
// from still views (rendered or real): each view held for a while with hand
// tremor (a random walk of the image, sub-pixel to a pixel), moves between
// views as motion-blurred cross-fades, the exposure drifting, every frame
// JPEG-compressed. Frames go to a folder, which live_calibrator plays at
// the video's frame rate.
#pragma once

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace portcal::testing {

struct HandHeldVideoOptions {
  double fps = 12.5;
  double hold_s = 1.5;      // each view held this long
  double move_s = 0.8;      // between views
  double tremor_px = 0.15;  // the tremor's standard deviation
  int blur_px = 31;         // length of the motion blur while moving
  double exposure = 0.03;   // relative amplitude of the exposure's drift
  int jpeg_quality = 90;
  unsigned seed = 1;
};

struct HandHeldVideo {
  double fps = 0;
  std::vector<std::pair<double, double>> holds;  // each view's [start, end) media time, s
};

// Frames f00000.jpg ... in `folder`, a hold per still in order.
inline HandHeldVideo WriteHandHeldVideo(const std::vector<cv::Mat>& stills,
                                        const std::filesystem::path& folder,
                                        const HandHeldVideoOptions& options) {
  std::filesystem::create_directories(folder);
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> normal(0, 1);
  HandHeldVideo video{options.fps, {}};
  int index = 0;
  auto write = [&](const cv::Mat& frame, int step) {
    // Exposure drifts slowly, as a camera's auto-exposure does.
    cv::Mat exposed;
    frame.convertTo(exposed, -1, 1 + options.exposure * std::sin(0.2 * step), 0);
    char name[32];
    std::snprintf(name, sizeof(name), "f%05d.jpg", index++);
    cv::imwrite((folder / name).string(), exposed,
                {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
  };
  const int hold_frames = static_cast<int>(options.hold_s * options.fps);
  const int move_frames = static_cast<int>(options.move_s * options.fps);
  for (size_t v = 0; v < stills.size(); ++v) {
    const cv::Mat& still = stills[v];
    video.holds.emplace_back(index / options.fps, (index + hold_frames) / options.fps);
    // Tremor: a damped random walk whose spread is tremor_px.
    double x = 0, y = 0;
    for (int f = 0; f < hold_frames; ++f) {
      x = 0.8 * x + 0.6 * options.tremor_px * normal(rng);
      y = 0.8 * y + 0.6 * options.tremor_px * normal(rng);
      const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, x, 0, 1, y);
      cv::Mat frame;
      cv::warpAffine(still, frame, shift, still.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
      write(frame, index);
    }
    if (v + 1 == stills.size()) break;
    for (int f = 0; f < move_frames; ++f) {
      const double a = (f + 1.0) / (move_frames + 1.0);
      cv::Mat mixed, moved, blurred;
      cv::addWeighted(still, 1 - a, stills[v + 1], a, 0, mixed);
      const cv::Mat sweep = (cv::Mat_<double>(2, 3) << 1, 0, 40 * std::sin(CV_PI * a), 0, 1, 0);
      cv::warpAffine(mixed, moved, sweep, mixed.size());
      cv::blur(moved, blurred, cv::Size(options.blur_px, 1));
      write(blurred, index);
    }
  }
  return video;
}

}  // namespace portcal::testing
