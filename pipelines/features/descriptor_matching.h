// Nearest-neighbour matching of COLMAP-normalised SIFT descriptors, with
// COLMAP's tests: the distance is the angle between the (unit) descriptors,
// a match needs angle <= max_distance, best < max_ratio x second best
// (Lowe's ratio test) and, with cross_check, to be mutual.
#pragma once

#include "database/feature_types.h"

namespace portcal {

struct DescriptorMatchingOptions {
  double max_ratio = 0.8;
  double max_distance = 0.7;  // radians between unit descriptors
  bool cross_check = true;
  int max_num_matches = 32768;
  void Check() const;  // throws OptionError naming --SiftMatching.*
};

// Descriptors as unit float rows (uint8 / 512, renormalised).
using UnitDescriptors = Eigen::Matrix<float, Eigen::Dynamic, 128, Eigen::RowMajor>;
UnitDescriptors ToUnitDescriptors(const FeatureDescriptors& descriptors);

FeatureMatches MatchDescriptors(const UnitDescriptors& descriptors1,
                                const UnitDescriptors& descriptors2,
                                const DescriptorMatchingOptions& options);

}  // namespace portcal
