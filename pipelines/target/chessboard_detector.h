// Chessboard detection: a count of X-junctions first turns away images that
// cannot hold the board (x_corner_count.h); coarse corners from OpenCV on a
// downscaled image (findChessboardCorners, then at full resolution, then
// findChessboardCornersSB as a fallback), put in portcal's canonical order (right-handed, corner
// 0's outer diagonal square black), then refined at full resolution by the ideal-pattern fit
// (corner_refinement.h). A board cut by the image's border: its part in view
// (partial_chessboard.h).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipelines/target/corner_refinement.h"
#include "pipelines/target/x_corner_count.h"

namespace portcal {

struct ChessboardDetectionOptions {
  int cols = 10;  // inner corners per row, >= 2
  int rows = 7;   // inner corners per column, >= 2
  // Coarse detection runs on the image halved (once or more) to at most
  // this many pixels on its longer side (0: full resolution only).
  int coarse_max_image_size = 1000;
  // Images with fewer grid junctions (x_corner_count.h; at that scale or
  // half of it) than this fraction of the board's (cols - 2) (rows - 2)
  // are not searched (0: all are). On the shared views boards count 0.54
  // to 1.0 of theirs, textured scenes without a board at most 0.05 of a
  // 10 x 7 board's (docs/benchmarks_target_detection.md).
  double min_x_corner_fraction = 0.25;
  // A view keeps the corners that refined; it is refused with fewer than
  // this many, or when they lie on one row or one column (no pose then).
  int min_refined_corners = 6;
  // false: the coarse corners are only polished by cv::cornerSubPix (5 x 5
  // window at full resolution): tenths of a pixel at video rate, for live
  // views; true: the ideal-pattern fit (hundredths, several times slower).
  bool precise_fit = true;
  // A board cut by the image's border is searched for when the whole board
  // is not found (partial_chessboard.h): the corners in view are kept where
  // their place on the board can be told.
  bool partial_views = true;
  CornerRefinementOptions refinement;
  void Check() const;  // throws OptionError
};

struct ChessboardDetection {
  bool found = false;
  std::string reason;  // why not, when not found
  // Canonical order: index r * cols + c, corner 0 the one whose outer
  // diagonal square is black (as the shared ground truth numbers them);
  // nullopt where the refinement rejected the corner.
  std::vector<std::optional<Eigen::Vector2d>> corners;  // COLMAP pixels
  // The board looks the same rotated by 180 degrees (an even number of
  // squares in total): the order may be the rotated one.
  bool symmetric = false;
  bool partial = false;  // the board was found in part (cut by the image's border)
  int num_refined = 0;
  // Found with corners left out: how many and why, e.g. "3 of 48 corners
  // left out (2 no contrast, 1 window beyond the image)".
  std::string note;
};

ChessboardDetection DetectChessboard(const cv::Mat& gray,
                                     const ChessboardDetectionOptions& options);

}  // namespace portcal
