// Chessboard detection: coarse corners from OpenCV on a downscaled image
// (findChessboardCorners with its fast check, then findChessboardCornersSB
// as a fallback), put in portcal's canonical order (right-handed, corner 0's
// outer diagonal square black), then refined at full resolution by the
// ideal-pattern fit (corner_refinement.h).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipelines/target/corner_refinement.h"

namespace portcal {

struct ChessboardDetectionOptions {
  int cols = 10;  // inner corners per row, >= 2
  int rows = 7;   // inner corners per column, >= 2
  // Coarse detection runs on the image halved (once or more) to at most
  // this many pixels on its longer side (0: full resolution only).
  int coarse_max_image_size = 1000;
  // Views with fewer refined corners than this fraction are rejected.
  double min_refined_fraction = 0.9;
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
  int num_refined = 0;
};

ChessboardDetection DetectChessboard(const cv::Mat& gray, const ChessboardDetectionOptions& options);

}  // namespace portcal
