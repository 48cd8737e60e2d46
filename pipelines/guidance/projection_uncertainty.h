// The expected uncertainty of projection over the image: how far (px, one
// standard deviation, worst direction) a point may land from where the
// calibration puts it, given the information the views carry on the
// unknowns. It is mrcal's measure of a calibration's quality (mrcal 2.2's
// projection_uncertainty, "mean-frames", worstdirection-stdev) in place of
// Calibration Wizard's trace of the intrinsics' covariance, which adds
// pixels to unitless distortion terms; and it applies unchanged to a
// housing's parameters, the point then in water.
//
// As mrcal, the point is held fixed in the targets' frames, not in the
// camera's: the camera frame is only defined through the views' poses, so
// an error of the principal point that the boards' rotations absorb moves
// no point seen through the target. The point is mapped into every view's
// target frame with the solved pose and back with the perturbed one, the
// results averaged (calibration_information.h has the first-order form).
// At infinity only the rotations matter. docs/calibration.md says what is
// propagated and how it compares with mrcal's own numbers.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pipelines/guidance/calibration_information.h"
#include "pipelines/guidance/calibration_unknowns.h"

namespace portcal {

struct ProjectionUncertaintyOptions {
  double working_distance_m = 1.0;  // depth (z, camera frame) of the points, > 0
  int grid_cols = 16;               // evaluation points across the image, >= 2
  int grid_rows = 9;                // >= 2
  double pixel_sigma_px = 0.1;      // a corner's noise, > 0
  void Check() const;               // throws OptionError naming the field
};

struct ProjectionUncertainty {
  bool determined = false;  // the views fix every unknown
  double mean_px = 0;       // at the working distance, over the grid points that project
  double max_px = 0;
  double mean_at_infinity_px = 0;
  double max_at_infinity_px = 0;
  // grid_rows x grid_cols; -1 where no ray (or undetermined).
  Eigen::MatrixXd map_px;              // at the working distance
  Eigen::MatrixXd map_at_infinity_px;  // at infinity
};

// The grid's cell centres (COLMAP pixels): x per column, y per row.
Eigen::VectorXd UncertaintyGridColumns(double image_width, int grid_cols);
Eigen::VectorXd UncertaintyGridRows(double image_height, int grid_rows);

// The grid's rays through the current estimate are computed once; then any
// information (the kept views', plus a candidate's) is scored.
class ProjectionUncertaintyModel {
 public:
  ProjectionUncertaintyModel(const CalibrationUnknowns& unknowns,
                             const ProjectionUncertaintyOptions& options);

  // `information`: NumUnknowns() unknowns, unit pixel variance (it is
  // scaled by pixel_sigma_px^2 here).
  ProjectionUncertainty Evaluate(const CalibrationInformation& information) const;

 private:
  // One depth's grid: the points and their Jacobians.
  struct GridPoints {
    std::vector<Eigen::Vector3d> points;
    ProjectionJacobians jacobians;
  };
  // Worst-direction sigma at every grid point (-1 where none).
  Eigen::MatrixXd Sigmas(const GridPoints& grid, const CalibrationInformation& information,
                         const Eigen::MatrixXd& covariance) const;

  ProjectionUncertaintyOptions options_;
  int num_unknowns_ = 0;
  std::vector<bool> projects_;  // per grid point
  GridPoints at_distance_, at_infinity_;
};

}  // namespace portcal
