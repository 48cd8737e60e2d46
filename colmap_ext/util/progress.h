// Progress of long loops, reported to a caller-supplied sink, and a cancel
// flag polled by the loop (set by SIGINT/SIGTERM in the executable).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace portcal {

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // Starts a phase of `total` items (images, pairs, ...).
  virtual void Begin(const std::string& what, size_t total) = 0;
  // Thread-safe: `count` more items are done.
  virtual void Advance(size_t count = 1) = 0;
  virtual void End() = 0;
};

// Swallows everything (tests, library callers that do not care).
class NullProgress : public ProgressSink {
 public:
  void Begin(const std::string&, size_t) override {}
  void Advance(size_t) override {}
  void End() override {}
};

// "what: done/total (xx%), rate/s, ETA mm:ss" on stderr, at most once per
// `min_interval_s`, and a final line. Silent below log level info.
class StderrProgress : public ProgressSink {
 public:
  explicit StderrProgress(double min_interval_s = 1.0);
  void Begin(const std::string& what, size_t total) override;
  void Advance(size_t count = 1) override;
  void End() override;

 private:
  void Print(bool final_line);

  std::mutex mutex_;
  std::string what_;
  size_t total_ = 0;
  size_t done_ = 0;
  double min_interval_s_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
};

// Global cancel request (set from a signal handler: lock-free atomic).
class CancelFlag {
 public:
  static void Request() { flag().store(true); }
  static bool Requested() { return flag().load(); }
  static void Reset() { flag().store(false); }
  // Throws Cancelled if a stop was requested.
  static void ThrowIfRequested();

 private:
  static std::atomic<bool>& flag();
};

}  // namespace portcal
