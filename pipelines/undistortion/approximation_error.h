// How good a virtual pinhole is behind a port: the error of the
// approximation (output pixels) over the output image at the depths of a
// range, and the design depth that makes the worst of it smallest.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipelines/undistortion/virtual_pinhole.h"

namespace portcal {

// Depths (z in the camera frame, metres) the scene is expected at.
struct DepthRange {
  double near = 0;
  double far = 0;
};

// The error over the output image at one depth.
struct DepthError {
  double depth = 0;
  double max_px = 0;
  double mean_px = 0;
  double p95_px = 0;
  // Per cell of a grid over the output image (cell centres), -1 where the
  // output shows nothing of the camera's image (HeatMapPicture's grey).
  Eigen::MatrixXd grid;
};

struct ApproximationError {
  std::vector<DepthError> depths;  // increasing depth; the range's ends included
  double worst_px = 0;             // over every depth and cell
  double worst_depth = 0;
};

// Depths spread evenly in log over `range` (`count` >= 2 of them), plus
// the design depth if it lies inside and is not one of them.
std::vector<double> SampleDepths(const DepthRange& range, int count, double design_depth);

// The error at each of `depths` on a `grid_cols` wide grid (rows in the
// output's aspect), rows computed on `num_threads` threads.
ApproximationError MeasureApproximationError(const VirtualPinhole& pinhole,
                                             const std::vector<double>& depths, int grid_cols,
                                             int num_threads);

// The design depth in `range` whose pinhole (fitted as `field_of_view`
// says) has the smallest worst error over the range: golden-section search
// in log depth on a coarse grid. In air, the near end (any depth is exact).
double ChooseDesignDepth(const HousedCamera& camera, const DepthRange& range,
                         const Eigen::Matrix3d& pinhole_from_cam,
                         const FieldOfViewOptions& field_of_view);

}  // namespace portcal
