// Logging goes through glog (Ceres uses it too). `--log_level` maps onto it.
#pragma once

#include <glog/logging.h>

#include <string>

namespace portcal {

// "error" | "warn" | "info" | "debug". Throws OptionError otherwise. Also
// routes glog to stderr only (no log files); Ceres' own messages appear at
// "debug" only, marked "(Ceres)".
void SetLogLevel(const std::string& level);

// True for a source file of Ceres' (whose messages are kept to the debug
// log).
bool IsCeresSource(const char* full_filename);

// Idempotent glog set-up for executables and tests.
void InitializeLogging(const char* program_name);

}  // namespace portcal
