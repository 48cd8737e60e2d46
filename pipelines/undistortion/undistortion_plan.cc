#include "pipelines/undistortion/undistortion_plan.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/undistortion/stereo_rectification.h"

namespace portcal {
namespace {

// The camera's design depth and error range from the options or its points.
void ChooseDepths(const UndistortionPlanOptions& options, const HousedCamera& camera,
                  const std::optional<DepthRange>& points, CameraUndistortion* plan) {
  const Eigen::Matrix3d& rotation = plan->pinhole.pinhole_from_cam;
  const std::string name = "camera " + std::to_string(camera.camera.camera_id);
  const bool range_given = options.depth_range.far > 0;
  if (range_given) {
    plan->range = options.depth_range;
  } else if (options.distance > 0) {
    plan->range = {options.distance / 2, options.distance * 2};
  } else if (points) {
    plan->range = *points;
  } else if (camera.housing) {
    throw InputError(
        name + " sits behind a " + camera.housing->ModelName() +
        " and there are no points to take its depths from: give --Undistort.distance or "
        "--Undistort.depth_range (metres)");
  } else {
    plan->range = {1.0, 1.0};  // in air every depth maps alike
  }
  const double reach = HousingReach(camera);
  const double nearest =
      options.distance > 0 ? std::min(options.distance, plan->range.near) : plan->range.near;
  if (!(nearest > reach)) {
    const std::string option = range_given            ? "--Undistort.depth_range"
                               : options.distance > 0 ? "--Undistort.distance"
                                                      : "the model's point depths";
    throw InputError(option + ": " + FormatShortest(nearest) + " m is inside " + name +
                     "'s housing, whose port reaches z = " + FormatFixed(reach, 4) + " m");
  }
  const std::string range_words = range_given ? "--Undistort.depth_range"
                                  : options.distance > 0
                                      ? "half to twice the distance"
                                      : "5th-95th percentile of the model's point depths";
  if (options.distance > 0) {
    plan->pinhole.design_depth = options.distance;
    plan->depth_choice = "--Undistort.distance; error over " + range_words;
  } else {
    plan->pinhole.design_depth =
        ChooseDesignDepth(camera, plan->range, rotation, options.field_of_view);
    plan->depth_choice = "the smallest worst error over " + range_words;
  }
}

// The error of `plan`'s pinhole over its range.
void MeasureError(const UndistortionPlanOptions& options, CameraUndistortion* plan) {
  const std::vector<double> depths =
      plan->range.far > plan->range.near
          ? SampleDepths(plan->range, options.num_error_depths, plan->pinhole.design_depth)
          : std::vector<double>{plan->range.near};
  plan->error = MeasureApproximationError(plan->pinhole, depths, 64, options.num_threads);
}

// A rig's two cameras as rectified pinholes.
std::vector<CameraUndistortion> PlanRectifiedPair(const UndistortionPlanOptions& options,
                                                  const SparseModel& model,
                                                  const Rigid3d& cam2_from_cam1) {
  const RectifyingRotations rotations = RectifyingRotationsOf(cam2_from_cam1);
  std::vector<CameraUndistortion> plans;
  for (camera_t id : {1u, 2u}) {
    const auto housing = model.housings.find(id);
    const HousedCamera camera{model.cameras.at(id), housing == model.housings.end()
                                                        ? std::nullopt
                                                        : std::optional<Housing>(housing->second)};
    plans.push_back(PlanCamera(options, camera, std::nullopt,
                               id == 1 ? rotations.rect_from_cam1 : rotations.rect_from_cam2));
  }
  std::tie(plans[0].pinhole, plans[1].pinhole) = FitRectifiedPinholes(
      plans[0].pinhole.source, plans[1].pinhole.source, rotations, plans[0].pinhole.design_depth,
      plans[1].pinhole.design_depth, options.field_of_view);
  for (size_t i = 0; i < 2; ++i) {
    MeasureError(options, &plans[i]);
    plans[i].stereo_partner = i == 0 ? 2 : 1;
    plans[i].rectified_baseline = rotations.baseline;
  }
  return plans;
}

}  // namespace

void UndistortionPlanOptions::Check() const {
  field_of_view.Check();
  if (!(distance >= 0) || !std::isfinite(distance)) {
    throw OptionError("--Undistort.distance", FormatShortest(distance),
                      "a depth in metres (> 0), or 0: not given");
  }
  const bool no_range = depth_range.near == 0 && depth_range.far == 0;
  if (!no_range && !(depth_range.near > 0 && depth_range.far >= depth_range.near &&
                     std::isfinite(depth_range.far))) {
    throw OptionError("--Undistort.depth_range",
                      FormatShortest(depth_range.near) + "," + FormatShortest(depth_range.far),
                      "NEAR,FAR in metres with 0 < NEAR <= FAR");
  }
  if (num_error_depths < 2 || num_error_depths > 50) {
    throw OptionError("--Undistort.num_error_depths", num_error_depths, "2 to 50");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

std::optional<DepthRange> PointDepthRange(const SparseModel& model, camera_t camera_id) {
  std::vector<double> depths;
  for (const auto& [image_id, image] : model.images) {
    if (image.camera_id != camera_id) continue;
    for (const Point2D& point2D : image.points2D) {
      const auto point = model.points3D.find(point2D.point3D_id);
      if (point == model.points3D.end()) continue;
      const double z = (image.cam_from_world * point->second.xyz).z();
      if (z > 0) depths.push_back(z);
    }
  }
  if (depths.size() < 10) return std::nullopt;
  std::sort(depths.begin(), depths.end());
  const auto at = [&](double q) {
    return depths[static_cast<size_t>(q * static_cast<double>(depths.size() - 1))];
  };
  return DepthRange{at(0.05), std::max(at(0.95), at(0.05))};
}

CameraUndistortion PlanCamera(const UndistortionPlanOptions& options, const HousedCamera& camera,
                              const std::optional<DepthRange>& points,
                              const Eigen::Matrix3d& pinhole_from_cam) {
  CameraUndistortion plan;
  plan.pinhole.pinhole_from_cam = pinhole_from_cam;
  ChooseDepths(options, camera, points, &plan);
  plan.pinhole =
      FitVirtualPinhole(camera, plan.pinhole.design_depth, pinhole_from_cam, options.field_of_view);
  MeasureError(options, &plan);
  return plan;
}

std::vector<CameraUndistortion> PlanUndistortion(const UndistortionPlanOptions& options,
                                                 const SparseModel& model,
                                                 const std::optional<Rigid3d>& cam2_from_cam1) {
  if (cam2_from_cam1) return PlanRectifiedPair(options, model, *cam2_from_cam1);
  std::vector<CameraUndistortion> plans;
  for (const auto& [camera_id, camera] : model.cameras) {
    const auto housing = model.housings.find(camera_id);
    const HousedCamera housed{camera, housing == model.housings.end()
                                          ? std::nullopt
                                          : std::optional<Housing>(housing->second)};
    plans.push_back(PlanCamera(options, housed, PointDepthRange(model, camera_id),
                               Eigen::Matrix3d::Identity()));
  }
  return plans;
}

}  // namespace portcal
