// Nearest-neighbour matching of COLMAP-normalised SIFT descriptors, with
// COLMAP's tests: the distance is the angle between the (unit) descriptors,
// a match needs angle <= max_distance, best < max_ratio x second best
// (Lowe's ratio test) and, with cross_check, to be mutual.
//
// Brute force compares every pair of descriptors (COLMAP's CPU matcher;
// nearest_descriptors.h);
// "kdtree" finds the two nearest neighbours by FLANN's randomized k-d trees
// (Muja and Lowe, "Fast approximate nearest neighbors with automatic
// algorithm configuration", VISAPP 2009). At 128 dimensions and ~4500
// features per image the trees gain little (measured on two survey images:
// 0.16 s at 32 checks, 99 % of the matches, against 0.24 s brute force
// before its AVX2 kernel, ~0.05 s since; slower from 64 checks on), so
// brute force is the default (docs/dev/auto_calibration_notes.md).
#pragma once

#include <string>

#include "colmap_ext/feature/keypoint.h"
#include "colmap_ext/feature/two_view_geometry.h"
#include "pipelines/features/nearest_descriptors.h"

namespace portcal {

struct DescriptorMatchingOptions {
  double max_ratio = 0.8;
  double max_distance = 0.7;  // radians between unit descriptors
  bool cross_check = true;
  int max_num_matches = 32768;
  std::string method = "brute_force";  // brute_force | kdtree
  int kdtree_num_trees = 4;
  int kdtree_num_checks = 128;  // leaves visited per query
  void Check() const;           // throws OptionError naming --SiftMatching.*
};

// Descriptors as unit float rows (uint8 / 512, renormalised).
using UnitDescriptors = UnitDescriptorRows;
UnitDescriptors ToUnitDescriptors(const FeatureDescriptors& descriptors);

FeatureMatches MatchDescriptors(const UnitDescriptors& descriptors1,
                                const UnitDescriptors& descriptors2,
                                const DescriptorMatchingOptions& options);

}  // namespace portcal
