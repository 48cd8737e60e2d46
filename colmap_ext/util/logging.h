// Logging goes through glog (Ceres uses it too). `--log_level` maps onto it.
#pragma once

#include <glog/logging.h>

#include <string>

namespace portcal {

// "error" | "warn" | "info" | "debug". Throws OptionError otherwise. Also
// routes glog to stderr only (no log files).
void SetLogLevel(const std::string& level);

// Idempotent glog set-up for executables and tests.
void InitializeLogging(const char* program_name);

}  // namespace portcal
