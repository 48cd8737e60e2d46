#include "colmap_ext/util/progress.h"

#include <glog/logging.h>

#include <cstdio>

#include "colmap_ext/util/error.h"

namespace portcal {

StderrProgress::StderrProgress(double min_interval_s) : min_interval_s_(min_interval_s) {}

void StderrProgress::Begin(const std::string& what, size_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  what_ = what;
  total_ = total;
  done_ = 0;
  start_ = last_print_ = std::chrono::steady_clock::now();
}

void StderrProgress::Advance(size_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += count;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_print_).count() >= min_interval_s_) {
    last_print_ = now;
    Print(false);
  }
}

void StderrProgress::End() {
  std::lock_guard<std::mutex> lock(mutex_);
  Print(true);
}

void StderrProgress::Print(bool final_line) {
  if (FLAGS_minloglevel > google::GLOG_INFO) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? done_ / elapsed : 0.0;
  const double percent = total_ > 0 ? 100.0 * done_ / total_ : 100.0;
  if (final_line) {
    std::fprintf(stderr, "%s: %zu/%zu done in %.1f s (%.2f/s)\n", what_.c_str(), done_, total_,
                 elapsed, rate);
    return;
  }
  const double eta = rate > 0 ? (total_ - done_) / rate : 0.0;
  std::fprintf(stderr, "%s: %zu/%zu (%.0f%%), %.2f/s, ETA %02d:%02d\n", what_.c_str(), done_,
               total_, percent, rate, static_cast<int>(eta) / 60, static_cast<int>(eta) % 60);
}

std::atomic<bool>& CancelFlag::flag() {
  static std::atomic<bool> requested{false};
  return requested;
}

void CancelFlag::ThrowIfRequested() {
  if (Requested()) throw Cancelled();
}

}  // namespace portcal
