// The small rendered survey the survey tests share (survey_calibration_test,
// hierarchical_mapper_test): 48 images of 640 x 360 in a lawnmower path 2 m
// over a rough seabed behind a flat port tilted 3 deg, navigation of 2 cm
// noise; rendered, extracted (the 1500 strongest features: a CI-sized
// survey), its navigation imported and spatially matched.
#pragma once

#include <string>

#include "colmap_ext/io/ground_truth.h"
#include "tests/test_utils.h"

namespace portcal {
namespace testing {

struct MatchedSurvey {
  std::string database;
  std::string image_path;
  GroundTruth truth;
  int num_position_priors = 0;
};

// `survey_keys`: more keys of the config's survey block (", markers: {...}").
MatchedSurvey RenderAndMatchTestSurvey(const TempDir& dir, const std::string& survey_keys = "");

}  // namespace testing
}  // namespace portcal
