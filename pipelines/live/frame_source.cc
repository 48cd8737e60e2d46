#include "pipelines/live/frame_source.h"

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/images/image_reader.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool AllDigits(const std::string& text) {
  return !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

void FrameSourceOptions::Check() const {
  if (source.empty())
    throw OptionError("--source", "''", "a device, video file, folder, URL or GStreamer pipeline");
  if (!(folder_fps > 0)) throw OptionError("--Live.fps", folder_fps, "> 0");
  if (!(stall_seconds > 0)) throw OptionError("--Live.stall_seconds", stall_seconds, "> 0 s");
}

SourceKind ClassifySource(const std::string& source) {
  if (AllDigits(source) || source.rfind("/dev/video", 0) == 0) return SourceKind::kDevice;
  if (source.find("appsink") != std::string::npos || source.find(" ! ") != std::string::npos) {
    return SourceKind::kPipeline;
  }
  if (source.find("://") != std::string::npos) return SourceKind::kNetwork;
  std::error_code error;
  if (fs::is_directory(source, error)) return SourceKind::kFolder;
  return SourceKind::kFile;
}

// The newest frame of a live source, written by the reader thread.
struct FrameSource::Shared {
  cv::VideoCapture capture;
  std::mutex mutex;
  std::condition_variable changed;
  cv::Mat newest;
  int64_t count = 0;  // frames read so far
  bool ended = false;
  bool stop = false;
  double start_wall_s = 0;
  double newest_wall_s = 0;  // when the newest frame arrived
};

FrameSource::FrameSource(const FrameSourceOptions& options) : options_(options) {
  options.Check();
  const std::string& source = options.source;
  kind_ = ClassifySource(source);
  std::error_code error;
  if (kind_ == SourceKind::kFolder) {
    folder_images_ = ListImages(source);
    if (folder_images_.empty()) throw InputError(source + ": no images in the folder");
    fps_ = options.folder_fps;
    return;
  }
  if (kind_ == SourceKind::kDevice && !AllDigits(source) && !fs::exists(source, error)) {
    throw InputError(
        source +
        ": no such video device (is the camera plugged in? `v4l2-ctl --list-devices` lists them)");
  }
  if (kind_ == SourceKind::kFile && !fs::exists(source, error)) {
    throw InputError(source + ": no such file, folder or device");
  }
  auto capture = std::make_unique<cv::VideoCapture>();
  if (kind_ == SourceKind::kDevice) {
    if (AllDigits(source)) {
      // /dev/video0 .. /dev/video9999: a longer number is no device index.
      if (source.size() > 4)
        throw InputError(source + ": no such video device index (0 to 9999, /dev/videoN)");
      capture->open(std::stoi(source), cv::CAP_V4L2);
    } else {
      capture->open(source, cv::CAP_V4L2);
    }
  } else if (kind_ == SourceKind::kPipeline) {
    capture->open(source, cv::CAP_GSTREAMER);
  } else if (kind_ == SourceKind::kNetwork) {
    const int timeout_ms = static_cast<int>(1000 * options.stall_seconds);
    capture->open(
        source, cv::CAP_FFMPEG,
        {cv::CAP_PROP_OPEN_TIMEOUT_MSEC, timeout_ms, cv::CAP_PROP_READ_TIMEOUT_MSEC, timeout_ms});
  } else {
    capture->open(source, cv::CAP_ANY);
  }
  if (!capture->isOpened()) {
    throw InputError(source + ": OpenCV cannot open it as a " +
                     (kind_ == SourceKind::kDevice ? std::string("V4L2 device")
                      : kind_ == SourceKind::kPipeline
                          ? std::string("GStreamer pipeline (it must end in appsink)")
                      : kind_ == SourceKind::kNetwork ? std::string("network stream")
                                                      : std::string("video file")));
  }
  fps_ = capture->get(cv::CAP_PROP_FPS);
  if (!(fps_ > 0 && fps_ < 1000)) fps_ = options.folder_fps;
  if (!live()) {
    capture_ = std::move(capture);
    return;
  }
  shared_ = std::make_shared<Shared>();
  shared_->capture = std::move(*capture);
  shared_->start_wall_s = WallSeconds();
  // The reader owns a share of the state: a read stuck in a stalled stream
  // cannot outlive what it writes to.
  std::thread([shared = shared_] {
    cv::Mat image;
    while (true) {
      {
        const std::lock_guard<std::mutex> lock(shared->mutex);
        if (shared->stop) break;
      }
      const bool ok = shared->capture.read(image);
      const std::lock_guard<std::mutex> lock(shared->mutex);
      if (!ok || image.empty()) {
        shared->ended = true;
        shared->changed.notify_all();
        break;
      }
      shared->newest = image.clone();
      shared->newest_wall_s = WallSeconds();
      ++shared->count;
      shared->changed.notify_all();
    }
  }).detach();
}

FrameSource::~FrameSource() {
  if (shared_) {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->stop = true;
  }
}

std::string FrameSource::Describe() const {
  const std::string rate = std::to_string(static_cast<int>(std::lround(fps_)));
  switch (kind_) {
    case SourceKind::kDevice:
      return "V4L2 device " + options_.source;
    case SourceKind::kPipeline:
      return "GStreamer pipeline '" + options_.source + "'";
    case SourceKind::kNetwork:
      return "network stream " + options_.source;
    case SourceKind::kFolder:
      return "folder " + options_.source + " (" + std::to_string(folder_images_.size()) +
             " images at " + rate + " fps)";
    case SourceKind::kFile:
      break;
  }
  return "video file " + options_.source + " (" + rate + " fps)";
}

FrameStatus FrameSource::Next(Frame* frame) {
  return live() ? NextLive(frame) : NextRecorded(frame);
}

FrameStatus FrameSource::NextRecorded(Frame* frame) {
  const double now = WallSeconds();
  if (start_wall_s_ < 0) start_wall_s_ = now;
  if (options_.realtime) {
    // Late frames are dropped, early ones waited for: the file plays as the
    // camera that recorded it would have streamed.
    const int64_t due = static_cast<int64_t>((now - start_wall_s_) * fps_);
    const int64_t skip = std::max<int64_t>(0, due - next_index_);
    for (int64_t k = 0; k < skip; ++k) {
      if (capture_ && !capture_->grab()) return FrameStatus::kEnd;
      ++next_index_;
    }
    const double wait = start_wall_s_ + next_index_ / fps_ - WallSeconds();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  }
  frame->index = next_index_;
  frame->time_s = next_index_ / fps_;
  frame->arrival_wall_s = WallSeconds();
  if (kind_ == SourceKind::kFolder) {
    if (next_index_ >= static_cast<int64_t>(folder_images_.size())) return FrameStatus::kEnd;
    const fs::path path =
        fs::path(options_.source) / folder_images_[static_cast<size_t>(next_index_)];
    frame->image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (frame->image.empty()) LOG(WARNING) << path.string() << ": cannot read the image; skipped";
  } else if (!capture_->read(frame->image) || frame->image.empty()) {
    return FrameStatus::kEnd;
  }
  ++next_index_;
  return FrameStatus::kFrame;
}

FrameStatus FrameSource::NextLive(Frame* frame) {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  const int64_t seen = next_index_;
  const bool arrived =
      shared_->changed.wait_for(lock, std::chrono::duration<double>(options_.stall_seconds),
                                [&] { return shared_->count > seen || shared_->ended; });
  if (shared_->count > seen) {
    frame->image = shared_->newest;
    frame->time_s = shared_->newest_wall_s - shared_->start_wall_s;
    frame->arrival_wall_s = shared_->newest_wall_s;
    frame->index = shared_->count - 1;
    next_index_ = shared_->count;
    return FrameStatus::kFrame;
  }
  if (shared_->ended) return FrameStatus::kEnd;
  return arrived ? FrameStatus::kEnd : FrameStatus::kStalled;
}

}  // namespace portcal
