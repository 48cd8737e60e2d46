#include "colmap_ext/util/logging.h"

#include <atomic>
#include <cstdio>
#include <cstring>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

std::atomic<bool> debug_level{false};

// Writes glog's lines to stderr, except Ceres' own below --log_level debug.
// Ceres speaks of its internals ("Unable to perform dense Cholesky
// factorization", "Covariance matrix is near rank deficient"); portcal's
// reports say what that means for the calibration (which parameters the
// views leave undetermined, and what to change), so a user reads that, and
// Ceres' words stay in the debug log, marked as Ceres'.
class StderrSink : public google::LogSink {
 public:
  void send(google::LogSeverity severity, const char* full_filename, const char* base_filename,
            int line, const google::LogMessageTime& time, const char* message,
            size_t message_len) override {
    if (severity >= google::GLOG_FATAL) return;  // glog writes those itself
    const bool from_ceres = IsCeresSource(full_filename);
    if (from_ceres && !debug_level) return;
    std::string text = ToString(severity, base_filename, line, time, message, message_len);
    const size_t prefix_end = text.find("] ");
    if (from_ceres) text.insert(prefix_end == std::string::npos ? 0 : prefix_end + 2, "(Ceres) ");
    text += '\n';
    std::fwrite(text.data(), 1, text.size(), stderr);
  }
};

StderrSink& Sink() {
  static StderrSink sink;
  return sink;
}

// glog's own stderr output off (FATAL aside) and no log files: the sink
// writes instead.
void RouteThroughSink() {
  static bool routed = false;
  if (routed) return;
  routed = true;
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::GLOG_FATAL;
  for (const google::LogSeverity severity :
       {google::GLOG_INFO, google::GLOG_WARNING, google::GLOG_ERROR}) {
    google::SetLogDestination(severity, "");
  }
  google::AddLogSink(&Sink());
}

}  // namespace

bool IsCeresSource(const char* full_filename) {
  return full_filename != nullptr && std::strstr(full_filename, "internal/ceres/") != nullptr;
}

void InitializeLogging(const char* program_name) {
  static bool initialized = false;
  if (initialized) return;
  initialized = true;
  FLAGS_minloglevel = google::GLOG_INFO;
  google::InitGoogleLogging(program_name);
  RouteThroughSink();
}

void SetLogLevel(const std::string& level) {
  FLAGS_v = 0;
  debug_level = false;
  if (level == "error") {
    FLAGS_minloglevel = google::GLOG_ERROR;
  } else if (level == "warn") {
    FLAGS_minloglevel = google::GLOG_WARNING;
  } else if (level == "info") {
    FLAGS_minloglevel = google::GLOG_INFO;
  } else if (level == "debug") {
    FLAGS_minloglevel = google::GLOG_INFO;
    FLAGS_v = 2;
    debug_level = true;
  } else {
    throw OptionError("--log_level", level, "error, warn, info or debug");
  }
  RouteThroughSink();
}

}  // namespace portcal
