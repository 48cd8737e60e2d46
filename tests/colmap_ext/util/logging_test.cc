// --log_level and the stderr sink: Ceres' own messages only at debug
// (marked as Ceres'), portcal's at their level, nothing lost or doubled.
#include "colmap_ext/util/logging.h"

#include <gtest/gtest.h>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

std::string LoggedLines(const std::string& level) {
  SetLogLevel(level);
  testing::internal::CaptureStderr();
  // As Ceres' sources log it (their path as compiled into libceres).
  google::LogMessage("./internal/ceres/dense_cholesky.cc", 7, google::GLOG_WARNING).stream()
      << "Unable to perform dense Cholesky factorization.";
  LOG(WARNING) << "portcal warning";
  LOG(INFO) << "portcal info";
  return testing::internal::GetCapturedStderr();
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Logging, CeresMessagesOnlyInTheDebugLog) {
  InitializeLogging("logging_test");
  const std::string info = LoggedLines("info");
  EXPECT_EQ(Count(info, "Cholesky"), 0u) << info;
  EXPECT_EQ(Count(info, "portcal warning"), 1u) << info;
  EXPECT_EQ(Count(info, "portcal info"), 1u) << info;

  const std::string warn = LoggedLines("warn");
  EXPECT_EQ(Count(warn, "portcal warning"), 1u) << warn;
  EXPECT_EQ(Count(warn, "portcal info"), 0u) << warn;

  const std::string debug = LoggedLines("debug");
  EXPECT_EQ(Count(debug, "] (Ceres) Unable to perform dense Cholesky"), 1u) << debug;
  EXPECT_EQ(Count(debug, "dense_cholesky.cc:7]"), 1u) << debug;
  EXPECT_EQ(Count(debug, "portcal info"), 1u) << debug;
  SetLogLevel("info");
}

TEST(Logging, SourcesAndLevelsAreRecognised) {
  EXPECT_TRUE(IsCeresSource("./internal/ceres/covariance_impl.cc"));
  EXPECT_FALSE(IsCeresSource("pipelines/calibration/camera_calibration.cc"));
  EXPECT_FALSE(IsCeresSource(nullptr));
  EXPECT_THROW(SetLogLevel("verbose"), OptionError);
}

}  // namespace
}  // namespace portcal
