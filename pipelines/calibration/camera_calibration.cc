#include "pipelines/calibration/camera_calibration.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_reprojection_error.h"
#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/view_pose.h"
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

void CameraCalibrationSettings::Check() const {
  if (!(outlier_view_factor > 1)) {
    throw OptionError("--Calibration.outlier_view_factor", outlier_view_factor, "> 1");
  }
  if (min_points_per_view < 4) {
    throw OptionError("--Calibration.min_points_per_view", min_points_per_view, ">= 4");
  }
  if (max_num_iterations < 1) {
    throw OptionError("--Calibration.max_num_iterations", max_num_iterations, ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

Eigen::Vector4d BoardExtent(const std::vector<CalibrationView>& views) {
  Eigen::Vector4d extent(1e300, -1e300, 1e300, -1e300);
  for (const CalibrationView& view : views) ExtendBoardExtent(view, &extent);
  return extent;
}

void ExtendBoardExtent(const CalibrationView& view, Eigen::Vector4d* extent) {
  for (const Eigen::Vector3d& p : view.points_in_target) {
    *extent = Eigen::Vector4d(std::min((*extent)[0], p.x()), std::max((*extent)[1], p.x()),
                              std::min((*extent)[2], p.y()), std::max((*extent)[3], p.y()));
  }
}

std::vector<int> FixedParamIndices(const Camera& camera, const std::vector<std::string>& names) {
  std::set<int> fixed;
  const std::vector<std::string> param_names = SplitTokens(camera.ParamsInfo(), ", ");
  for (const std::string& name : names) {
    if (name == "focal") {
      for (int i : CameraModelFocalLengthIdxs(camera.model_id)) fixed.insert(i);
    } else if (name == "principal_point") {
      for (int i : CameraModelPrincipalPointIdxs(camera.model_id)) fixed.insert(i);
    } else if (name == "extra") {
      for (int i : CameraModelExtraParamsIdxs(camera.model_id)) fixed.insert(i);
    } else {
      const auto it = std::find(param_names.begin(), param_names.end(), name);
      if (it == param_names.end()) {
        throw OptionError("--Calibration.fixed_params", name,
                          "a parameter of " + camera.ModelName() + " (" + camera.ParamsInfo() +
                              "), focal, principal_point or extra");
      }
      fixed.insert(static_cast<int>(it - param_names.begin()));
    }
  }
  return {fixed.begin(), fixed.end()};
}

namespace {

struct Solution {
  std::vector<double> intrinsics;
  std::vector<std::array<double, 7>> poses;  // per kept view
  Eigen::Vector2d warp = Eigen::Vector2d::Zero();
  std::vector<double> params_std_dev;
  Eigen::MatrixXd params_covariance;
  Eigen::Vector2d warp_std_dev = Eigen::Vector2d::Zero();
  std::vector<double> view_rms;
  double sum_squares = 0;
  int num_residuals = 0;
  int num_free = 0;
};

void AddBoardResiduals(const std::vector<const CalibrationView*>& views, int model_id,
                       const Eigen::Vector4d& board_extent, Solution* s, ceres::Problem* problem) {
  VisitCameraModel(model_id, [&](auto model) {
    using Model = decltype(model);
    for (size_t v = 0; v < views.size(); ++v) {
      for (size_t i = 0; i < views[v]->pixels.size(); ++i) {
        const Eigen::Vector3d& p = views[v]->points_in_target[i];
        problem->AddResidualBlock(BoardReprojectionError<Model>::Create(
                                      p, BoardWarpUv(p, board_extent), views[v]->pixels[i]),
                                  nullptr, s->poses[v].data(), s->intrinsics.data(),
                                  s->warp.data());
      }
    }
  });
}

// Per-view RMS at the solution, and the sum of squares over all views.
void ComputeViewRms(const std::vector<const CalibrationView*>& views, int model_id,
                    const Eigen::Vector4d& board_extent, Solution* s) {
  double total = 0;
  int n = 0;
  VisitCameraModel(model_id, [&](auto model) {
    using Model = decltype(model);
    for (size_t v = 0; v < views.size(); ++v) {
      double sum = 0;
      for (size_t i = 0; i < views[v]->pixels.size(); ++i) {
        const Eigen::Quaterniond q(s->poses[v][3], s->poses[v][0], s->poses[v][1], s->poses[v][2]);
        Eigen::Vector3d p = views[v]->points_in_target[i];
        p.z() += BoardSag(s->warp.data(), BoardWarpUv(p, board_extent));
        const Eigen::Vector3d in_cam =
            q * p + Eigen::Vector3d(s->poses[v][4], s->poses[v][5], s->poses[v][6]);
        double x = 0, y = 0;
        if (!Model::ImgFromCam(s->intrinsics.data(), in_cam.x(), in_cam.y(), in_cam.z(), &x, &y)) {
          throw NumericalError(views[v]->image_name + ": a target point ends behind the camera");
        }
        sum += (Eigen::Vector2d(x, y) - views[v]->pixels[i]).squaredNorm();
      }
      s->view_rms.push_back(std::sqrt(sum / views[v]->pixels.size()));
      total += sum;
      n += static_cast<int>(views[v]->pixels.size());
    }
  });
  s->sum_squares = total;
  s->num_residuals = 2 * n;
}

// Covariance of the parameters, scaled by the residual variance: the
// observations' noise is estimated from the fit, not assumed to be 1 px.
void ComputeParamsCovariance(const std::vector<int>& fixed,
                             const CameraCalibrationSettings& settings, ceres::Problem* problem,
                             Solution* s) {
  const int num_params = static_cast<int>(s->intrinsics.size());
  const double dof = s->num_residuals - s->num_free;
  const double variance = dof > 0 ? s->sum_squares / dof : 0;
  ceres::Covariance covariance(CalibrationCovarianceOptions(settings.num_threads));
  std::vector<std::pair<const double*, const double*>> blocks = {
      {s->intrinsics.data(), s->intrinsics.data()}};
  if (settings.estimate_board_warp) blocks.emplace_back(s->warp.data(), s->warp.data());
  s->params_std_dev.assign(num_params, 0.0);
  s->params_covariance = Eigen::MatrixXd::Zero(num_params, num_params);
  if (static_cast<int>(fixed.size()) < num_params && covariance.Compute(blocks, problem)) {
    std::vector<double> c(num_params * num_params);
    covariance.GetCovarianceBlock(s->intrinsics.data(), s->intrinsics.data(), c.data());
    s->params_covariance =
        Eigen::Map<const Eigen::MatrixXd>(c.data(), num_params, num_params) * variance;
    for (int i = 0; i < num_params; ++i) {
      s->params_std_dev[i] = std::sqrt(std::max(0.0, c[i * num_params + i] * variance));
    }
    if (settings.estimate_board_warp) {
      double w[4];
      covariance.GetCovarianceBlock(s->warp.data(), s->warp.data(), w);
      s->warp_std_dev = Eigen::Vector2d(std::sqrt(std::max(0.0, w[0] * variance)),
                                        std::sqrt(std::max(0.0, w[3] * variance)));
    }
  } else if (static_cast<int>(fixed.size()) < num_params) {
    // Undetermined (-1, written as null), not 0, which means "held".
    for (int i = 0; i < num_params; ++i) {
      if (std::find(fixed.begin(), fixed.end(), i) == fixed.end()) s->params_std_dev[i] = -1.0;
    }
    LOG(WARNING)
        << "camera calibration: the covariance is rank deficient (a parameter the views do "
           "not determine); standard deviations undetermined";
  }
}

Solution Solve(const std::vector<const CalibrationView*>& views, const Camera& camera,
               std::vector<std::array<double, 7>> poses, const std::vector<int>& fixed,
               const Eigen::Vector4d& board_extent, const CameraCalibrationSettings& settings) {
  Solution s;
  s.intrinsics = camera.params;
  s.poses = std::move(poses);
  ceres::Problem problem;
  AddBoardResiduals(views, camera.model_id, board_extent, &s, &problem);
  for (auto& pose : s.poses) {
    problem.SetManifold(pose.data(), PoseManifold());
  }
  const int num_params = static_cast<int>(camera.params.size());
  if (static_cast<int>(fixed.size()) == num_params) {
    problem.SetParameterBlockConstant(s.intrinsics.data());
  } else if (!fixed.empty()) {
    problem.SetManifold(s.intrinsics.data(), new ceres::SubsetManifold(num_params, fixed));
  }
  if (!settings.estimate_board_warp) problem.SetParameterBlockConstant(s.warp.data());

  SolveCalibration(&problem, settings.max_num_iterations, settings.num_threads,
                   "camera calibration");
  for (double p : s.intrinsics) {
    if (!std::isfinite(p))
      throw NumericalError("camera calibration produced a non-finite parameter");
  }
  ComputeViewRms(views, camera.model_id, board_extent, &s);
  s.num_free = (num_params - static_cast<int>(fixed.size())) + 6 * static_cast<int>(views.size()) +
               (settings.estimate_board_warp ? 2 : 0);
  ComputeParamsCovariance(fixed, settings, &problem, &s);
  return s;
}

// The views with enough points, and the board's extent over them (x min,
// x max, y min, y max).
std::vector<const CalibrationView*> UsableViews(const std::vector<CalibrationView>& all_views,
                                                const CameraCalibrationSettings& settings,
                                                Eigen::Vector4d* extent) {
  std::vector<const CalibrationView*> views;
  *extent = BoardExtent({});
  for (const CalibrationView& view : all_views) {
    if (static_cast<int>(view.pixels.size()) < settings.min_points_per_view) continue;
    views.push_back(&view);
    ExtendBoardExtent(view, extent);
  }
  if (views.size() < 2) {
    throw NumericalError("camera calibration needs at least 2 views with >= " +
                         std::to_string(settings.min_points_per_view) + " points, got " +
                         std::to_string(views.size()));
  }
  return views;
}

// Zhang's closed form: the poses of the views and, unless held or not
// wanted, the pinhole part of *camera.
std::vector<std::array<double, 7>> StartFromZhang(const std::vector<const CalibrationView*>& views,
                                                  const std::vector<int>& fixed,
                                                  const CameraCalibrationSettings& settings,
                                                  Camera* camera) {
  std::vector<PlanarView> planar;
  for (const CalibrationView* view : views) {
    PlanarView p;
    for (const auto& x : view->points_in_target) p.target_xy.push_back(x.head<2>());
    p.pixels = view->pixels;
    planar.push_back(p);
  }
  const auto pinhole = InitializePinholeFromPlanarViews(planar, static_cast<int>(camera->width),
                                                        static_cast<int>(camera->height));
  if (!pinhole)
    throw NumericalError("Zhang initialisation failed: the views are too alike or too few");
  if (settings.initialize_from_data) {
    const std::vector<int> focal = CameraModelFocalLengthIdxs(camera->model_id);
    const std::vector<int> principal = CameraModelPrincipalPointIdxs(camera->model_id);
    const auto is_fixed = [&](int i) { return std::count(fixed.begin(), fixed.end(), i) > 0; };
    if (focal.size() == 1) {
      if (!is_fixed(focal[0])) camera->params[focal[0]] = 0.5 * (pinhole->fx + pinhole->fy);
    } else {
      if (!is_fixed(focal[0])) camera->params[focal[0]] = pinhole->fx;
      if (!is_fixed(focal[1])) camera->params[focal[1]] = pinhole->fy;
    }
    if (!is_fixed(principal[0])) camera->params[principal[0]] = pinhole->cx;
    if (!is_fixed(principal[1])) camera->params[principal[1]] = pinhole->cy;
  }
  std::vector<std::array<double, 7>> poses;
  for (const Rigid3d& pose : pinhole->cam_from_target) {
    const Eigen::Quaterniond q = pose.rotation.normalized();
    poses.push_back({q.x(), q.y(), q.z(), q.w(), pose.translation.x(), pose.translation.y(),
                     pose.translation.z()});
  }
  return poses;
}

double MedianViewRms(std::vector<double> view_rms) {
  std::sort(view_rms.begin(), view_rms.end());
  return view_rms[view_rms.size() / 2];
}

// The views left out of the final solve, each with its RMS when it was.
struct DroppedViews {
  std::vector<bool> dropped;
  std::vector<double> rms_px;
};

// Solves, and while outliers are dropped (up to 4 rounds), drops the views
// whose RMS exceeds outlier_view_factor x the median of the kept views and
// solves again. *camera and *poses hold the last solution.
Solution SolveDroppingOutliers(const std::vector<const CalibrationView*>& views,
                               const std::vector<int>& fixed, const Eigen::Vector4d& extent,
                               const CameraCalibrationSettings& settings, Camera* camera,
                               std::vector<std::array<double, 7>>* poses, DroppedViews* out) {
  out->dropped.assign(views.size(), false);
  out->rms_px.assign(views.size(), 0.0);
  Solution solution;
  for (int round = 0; round < 4; ++round) {
    std::vector<const CalibrationView*> kept;
    std::vector<std::array<double, 7>> kept_poses;
    for (size_t v = 0; v < views.size(); ++v) {
      if (!out->dropped[v]) {
        kept.push_back(views[v]);
        kept_poses.push_back((*poses)[v]);
      }
    }
    if (kept.size() < 2)
      throw NumericalError("camera calibration: fewer than 2 views left after dropping outliers");
    solution = Solve(kept, *camera, kept_poses, fixed, extent, settings);
    const double median = MedianViewRms(solution.view_rms);
    bool any_new = false;
    size_t k = 0;
    for (size_t v = 0; v < views.size(); ++v) {
      if (out->dropped[v]) continue;
      (*poses)[v] = solution.poses[k];
      if (settings.drop_outlier_views &&
          solution.view_rms[k] > settings.outlier_view_factor * median) {
        out->dropped[v] = true;
        out->rms_px[v] = solution.view_rms[k];
        any_new = true;
        LOG(WARNING) << views[v]->image_name << ": RMS " << solution.view_rms[k] << " px > "
                     << settings.outlier_view_factor << " x median " << median << " px; dropped";
      }
      ++k;
    }
    camera->params = solution.intrinsics;
    if (!any_new) break;
  }
  return solution;
}

CameraCalibrationResult ResultOf(const std::vector<const CalibrationView*>& views,
                                 const Camera& camera, const Solution& solution,
                                 const std::vector<std::array<double, 7>>& poses,
                                 const DroppedViews& dropped,
                                 const CameraCalibrationSettings& settings) {
  CameraCalibrationResult result;
  result.camera = camera;
  result.params_std_dev = solution.params_std_dev;
  result.params_covariance = solution.params_covariance;
  result.board_warp = solution.warp;
  result.board_warp_std_dev = solution.warp_std_dev;
  result.num_points = solution.num_residuals / 2;
  result.overall_rms_px = std::sqrt(solution.sum_squares / std::max(1, result.num_points));
  const double dof = solution.num_residuals - solution.num_free;
  result.residual_sigma_px = dof > 0 ? std::sqrt(solution.sum_squares / dof) : 0;
  const double median = MedianViewRms(solution.view_rms);
  size_t k = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    CalibratedView out;
    out.image_name = views[v]->image_name;
    out.num_points = static_cast<int>(views[v]->pixels.size());
    out.dropped = dropped.dropped[v];
    const auto& p = poses[v];
    out.cam_from_target = Rigid3d(Eigen::Quaterniond(p[3], p[0], p[1], p[2]).normalized(),
                                  Eigen::Vector3d(p[4], p[5], p[6]));
    if (dropped.dropped[v]) {
      out.rms_px = dropped.rms_px[v];
      out.outlier = true;
    } else {
      out.rms_px = solution.view_rms[k++];
      out.outlier = out.rms_px > settings.outlier_view_factor * median;
    }
    result.views.push_back(out);
  }
  return result;
}

}  // namespace

CameraCalibrationResult CalibrateCamera(const std::vector<CalibrationView>& all_views,
                                        const Camera& initial,
                                        const CameraCalibrationSettings& settings) {
  settings.Check();
  initial.Validate("initial camera");
  const std::vector<int> fixed = FixedParamIndices(initial, settings.fixed_params);
  Eigen::Vector4d extent;
  const std::vector<const CalibrationView*> views = UsableViews(all_views, settings, &extent);
  Camera camera = initial;
  std::vector<std::array<double, 7>> poses = StartFromZhang(views, fixed, settings, &camera);
  DroppedViews dropped;
  const Solution solution =
      SolveDroppingOutliers(views, fixed, extent, settings, &camera, &poses, &dropped);
  return ResultOf(views, camera, solution, poses, dropped, settings);
}

}  // namespace portcal
