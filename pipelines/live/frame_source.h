// Frames for a live calibration, all through cv::VideoCapture (Debian's
// OpenCV reads V4L2 devices, files and network streams through FFmpeg, and
// GStreamer pipelines), plus a folder of images played at a frame rate.
//
// A live source (a device, a network stream, a pipeline) is read on its own
// thread that keeps only the newest frame, as a camera drops frames when
// the viewer is busy; a file or folder is read in order, paced to its frame
// rate when `realtime` (frames that are late are skipped, as they would be
// live), else every frame as fast as it is asked for (tests, replays).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

namespace portcal {

struct FrameSourceOptions {
  // /dev/videoN or an index (V4L2), a video file, a folder of images, an
  // rtsp:// (or http://, udp://) URL, or a GStreamer pipeline ending in
  // appsink.
  std::string source;
  double folder_fps = 10;    // a folder's frame rate (a file's is its own), > 0
  bool realtime = true;      // files and folders: pace to the frame rate
  double stall_seconds = 5;  // a live source without a frame this long is stalled, > 0
  void Check() const;        // throws OptionError naming the --Live. option
};

enum class SourceKind { kDevice, kFile, kFolder, kNetwork, kPipeline };

struct Frame {
  cv::Mat image;              // as decoded (gray or BGR)
  double time_s = 0;          // media time (files, folders) or since the start (live)
  int64_t index = 0;          // frame number in the source
  double arrival_wall_s = 0;  // when it was read (steady clock, s): pairs live sources
};

enum class FrameStatus { kFrame, kEnd, kStalled };

class FrameSource {
 public:
  // Throws InputError naming the source: no such device, file or folder;
  // nothing OpenCV can open; an empty folder.
  explicit FrameSource(const FrameSourceOptions& options);
  ~FrameSource();
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;

  // The next frame; kEnd at the end of a file or folder (or when a live
  // source closes), kStalled when a live source gave nothing for
  // stall_seconds (the caller may wait again).
  FrameStatus Next(Frame* frame);

  SourceKind kind() const { return kind_; }
  bool live() const {
    return kind_ == SourceKind::kDevice || kind_ == SourceKind::kNetwork ||
           kind_ == SourceKind::kPipeline;
  }
  double fps() const { return fps_; }
  // "V4L2 device /dev/video0", "video file run.avi (10 fps)", ...
  std::string Describe() const;

 private:
  struct Shared;  // state the live reader thread shares (outlives us if it hangs)
  FrameStatus NextRecorded(Frame* frame);
  FrameStatus NextLive(Frame* frame);

  FrameSourceOptions options_;
  SourceKind kind_ = SourceKind::kFile;
  double fps_ = 0;
  std::vector<std::string> folder_images_;
  std::unique_ptr<cv::VideoCapture> capture_;  // a recorded file
  std::shared_ptr<Shared> shared_;             // live source
  int64_t next_index_ = 0;
  double start_wall_s_ = -1;
};

// What a source string names (no I/O beyond stat).
SourceKind ClassifySource(const std::string& source);

}  // namespace portcal
