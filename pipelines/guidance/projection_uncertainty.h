// The expected uncertainty of projection over the image: how far (px, one
// standard deviation, worst direction) a point at a working distance may
// land from where the calibration puts it, given the information the views
// carry on the unknowns. It is mrcal's measure of a calibration's quality
// in place of Calibration Wizard's trace of the intrinsics' covariance,
// which adds pixels to unitless distortion terms; and it applies unchanged
// to a housing's parameters. Unlike mrcal it holds the point fixed in the
// camera frame (no compensation of the boards' reference frame): it ranks
// views, and a person reads it as "pixels of doubt".
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

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
  double mean_px = 0;       // over the grid points that project
  double max_px = 0;
  Eigen::MatrixXd map_px;   // grid_rows x grid_cols; -1 where no ray
};

// The grid's rays through the current estimate are computed once; then any
// information matrix (the kept views', plus a candidate's) is scored.
class ProjectionUncertaintyModel {
 public:
  ProjectionUncertaintyModel(const CalibrationUnknowns& unknowns, const ProjectionUncertaintyOptions& options);

  // `information`: NumUnknowns() square, unit pixel variance (it is scaled
  // by pixel_sigma_px^2 here).
  ProjectionUncertainty Evaluate(const Eigen::MatrixXd& information) const;

 private:
  ProjectionUncertaintyOptions options_;
  int num_unknowns_ = 0;
  Eigen::MatrixXd jacobian_;     // 2 per grid point
  std::vector<bool> projects_;   // per grid point
};

}  // namespace portcal
