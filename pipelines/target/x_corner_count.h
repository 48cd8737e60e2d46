// A quick count of chessboard-like X-junctions in an image: whether a board
// of N inner corners can be in it at all, decided in milliseconds before
// OpenCV's detectors, which spend hundreds of milliseconds (half
// resolution) to seconds (1080p) on a textured image without a board, and
// whose own fast check lets such images through (docs/benchmarks_target_detection.md).
//
// The response at a pixel compares 16 samples on a ring around it (as in
// ChESS, Bennett & Lasenby 2014): opposite samples alike and those a
// quarter turn apart unlike (an X-junction: dark, light, dark, light
// quadrants) against opposite samples unlike (an edge) and the ring's mean
// against the centre's (a thin line or a spot). Normalised by the ring's
// spread it is near 1 at a junction whatever the contrast, low elsewhere.
// Connected regions above a threshold are junctions; those where two grid
// lines cross (equally spaced neighbours on opposite sides, two ways) are
// counted, at the image's scale and at half of it (blurred or large
// squares).
#pragma once

#include <limits>
#include <opencv2/core.hpp>

namespace portcal {

struct XCornerCountOptions {
  int ring_radius_px = 3;
  // A junction's response over the ring's spread (1 for an ideal one).
  double min_normalised_response = 0.6;
  // And at least this response (16 times gray levels; an ideal junction
  // gives ~12 to 16 times half its contrast): flat regions' noise stays
  // below it. Pixel noise can still pass both tests, which is why only
  // junctions on a grid are counted.
  double min_response = 20;
  // Two junctions on opposite sides of a third are on a grid line through
  // it when their distances to it, and their sum of offsets, agree within
  // this fraction of the distance.
  double spacing_tolerance = 0.2;
  void Check() const;  // throws OptionError
};

// The number of X-junctions where grid lines cross in an 8-bit gray image:
// the larger of the counts at its own scale and at half of it. A board of
// cols x rows inner corners has (cols - 2) (rows - 2) of them. The count
// stops once it reaches `enough` (the caller's threshold).
int CountXCorners(const cv::Mat& gray, const XCornerCountOptions& options = {},
                  int enough = std::numeric_limits<int>::max());

}  // namespace portcal
