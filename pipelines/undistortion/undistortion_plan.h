// How image_undistorter chooses each camera's virtual pinhole: the design
// depth and the depth range its error is reported over (from the options or
// the model's points), the pinhole fitted there (a rig's two rectified
// together) and its approximation error.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/io/sparse_model.h"
#include "pipelines/undistortion/undistortion_report.h"
#include "pipelines/undistortion/virtual_pinhole.h"

namespace portcal {

struct UndistortionPlanOptions {
  FieldOfViewOptions field_of_view;
  // Behind a port: the design depth (m, z in the camera frame), or the depth
  // range whose worst error the chosen design depth minimises; 0: not given.
  // With the distance alone the error is reported over [distance / 2,
  // 2 distance]; with neither, a model's range is that of its points
  // (5th-95th percentile of their depths in each camera).
  double distance = 0;
  DepthRange depth_range;
  int num_error_depths = 5;  // depths the error is reported at (the range's ends included)
  int num_threads = 2;

  void Check() const;  // throws OptionError naming --Undistort.*
};

// The depths (z in the camera frame) of the model's points in the images of
// `camera_id`, 5th to 95th percentile; nullopt with fewer than 10.
std::optional<DepthRange> PointDepthRange(const SparseModel& model, camera_t camera_id);

// One camera's plan: its pinhole looks along `pinhole_from_cam`; `points`:
// the depths of its model points, if any. Throws InputError when no depth
// is known behind a port, or the nearest lies inside the housing.
CameraUndistortion PlanCamera(const UndistortionPlanOptions& options, const HousedCamera& camera,
                              const std::optional<DepthRange>& points,
                              const Eigen::Matrix3d& pinhole_from_cam);

// The plans of all of `model`'s cameras: each on its own axis with the
// depths of its points; with `cam2_from_cam1`, cameras 1 and 2 as a
// rectified pair (same rotation, same focal length and rows).
std::vector<CameraUndistortion> PlanUndistortion(const UndistortionPlanOptions& options,
                                                 const SparseModel& model,
                                                 const std::optional<Rigid3d>& cam2_from_cam1);

}  // namespace portcal
