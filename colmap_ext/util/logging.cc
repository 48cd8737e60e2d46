#include "colmap_ext/util/logging.h"

#include "colmap_ext/util/error.h"

namespace portcal {

void InitializeLogging(const char* program_name) {
  static bool initialized = false;
  if (initialized) return;
  initialized = true;
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_INFO;
  google::InitGoogleLogging(program_name);
}

void SetLogLevel(const std::string& level) {
  FLAGS_logtostderr = true;
  FLAGS_v = 0;
  if (level == "error") {
    FLAGS_minloglevel = google::GLOG_ERROR;
  } else if (level == "warn") {
    FLAGS_minloglevel = google::GLOG_WARNING;
  } else if (level == "info") {
    FLAGS_minloglevel = google::GLOG_INFO;
  } else if (level == "debug") {
    FLAGS_minloglevel = google::GLOG_INFO;
    FLAGS_v = 2;
  } else {
    throw OptionError("--log_level", level, "error, warn, info or debug");
  }
}

}  // namespace portcal
