#include "pipelines/crosscheck/mrcal_calibration.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

extern "C" {
#include <mrcal/mrcal.h>
#include <suitesparse/cholmod.h>
}

namespace portcal {
namespace {

// A grid coordinate that must be an integer multiple of the spacing.
int GridIndex(double value, double spacing, const std::string& image) {
  const double index = value / spacing;
  if (std::abs(index - std::round(index)) > 1e-6 || index < -0.5) {
    throw InputError(image + ": target point at " + std::to_string(value) +
                     " m is not on a square grid of spacing " + std::to_string(spacing) +
                     " m; mrcal takes chessboards only");
  }
  return static_cast<int>(std::lround(index));
}

}  // namespace

BoardGrid InferBoardGrid(const std::vector<CalibrationView>& views) {
  // The spacing is the smallest gap between distinct coordinates; the origin
  // the smallest coordinate.
  std::set<double> xs, ys;
  for (const CalibrationView& view : views) {
    for (const Eigen::Vector3d& p : view.points_in_target) {
      if (std::abs(p.z()) > 1e-9) {
        throw InputError(view.image_name + ": target points are not planar (z = " +
                         std::to_string(p.z()) + " m); mrcal takes flat chessboards only");
      }
      xs.insert(std::round(p.x() * 1e9) / 1e9);
      ys.insert(std::round(p.y() * 1e9) / 1e9);
    }
  }
  if (xs.size() < 2 || ys.size() < 2)
    throw InputError("target observations: fewer than 2x2 corners");
  double spacing = std::numeric_limits<double>::max();
  for (const std::set<double>* values : {&xs, &ys}) {
    for (auto it = std::next(values->begin()); it != values->end(); ++it) {
      spacing = std::min(spacing, *it - *std::prev(it));
    }
  }
  BoardGrid grid;
  grid.spacing = spacing;
  grid.origin = Eigen::Vector2d(*xs.begin(), *ys.begin());
  grid.width_n = GridIndex(*xs.rbegin() - grid.origin.x(), spacing, "target") + 1;
  grid.height_n = GridIndex(*ys.rbegin() - grid.origin.y(), spacing, "target") + 1;
  return grid;
}

MrcalBoardSolve MrcalBoardSolveOf(const std::vector<CalibrationView>& views,
                                  const std::vector<Rigid3d>& cam_from_target,
                                  const BoardGrid& grid,
                                  std::vector<std::vector<int>>* pool_to_point) {
  PORTCAL_CHECK(views.size() == cam_from_target.size());
  const int per_board = grid.width_n * grid.height_n;
  MrcalBoardSolve solve;
  solve.width_n = grid.width_n;
  solve.height_n = grid.height_n;
  solve.spacing = grid.spacing;
  solve.observations.assign(views.size() * per_board * 3, 0.0);
  if (pool_to_point) pool_to_point->assign(views.size(), std::vector<int>(per_board, -1));
  // mrcal's board frame starts at the first corner.
  const Rigid3d target_from_board(Eigen::Quaterniond::Identity(),
                                  Eigen::Vector3d(grid.origin.x(), grid.origin.y(), 0));
  for (size_t f = 0; f < views.size(); ++f) {
    const CalibrationView& view = views[f];
    double* block = &solve.observations[f * per_board * 3];
    for (int k = 0; k < per_board; ++k) block[3 * k + 2] = -1;
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      const Eigen::Vector3d& p = view.points_in_target[i];
      const int col = GridIndex(p.x() - grid.origin.x(), grid.spacing, view.image_name);
      const int row = GridIndex(p.y() - grid.origin.y(), grid.spacing, view.image_name);
      const int k = row * grid.width_n + col;
      // mrcal's pixels: the top-left pixel's centre at (0, 0).
      block[3 * k] = view.pixels[i].x() - 0.5;
      block[3 * k + 1] = view.pixels[i].y() - 0.5;
      block[3 * k + 2] = 1.0;
      if (pool_to_point) (*pool_to_point)[f][k] = static_cast<int>(i);
    }
    solve.frames_rt_toref.push_back(RtFromRigid(cam_from_target[f] * target_from_board));
  }
  return solve;
}

namespace {

// mrcal's problem for one camera and its board views, and what maps it
// back: pool entries to the views' corners, which were missing.
struct MrcalProblem {
  BoardGrid grid;
  mrcal_lensmodel_t lensmodel;
  int num_frames = 0;
  int per_board = 0;
  std::vector<mrcal_point3_t> pool;
  std::vector<std::vector<int>> pool_to_point;
  std::vector<char> missing;
  std::vector<mrcal_observation_board_t> observations;
  std::vector<mrcal_pose_t> frames;
  std::vector<double> intrinsics;
  mrcal_calobject_warp_t warp = {{0, 0}};
  int imagersize[2] = {0, 0};
  mrcal_problem_selections_t selections;
  mrcal_problem_constants_t constants = {-1.0, -1.0};
  int num_points = 0;
};

// One board observation per view, a dense (H, W) block of the pool each;
// corners the detector did not report are marked as outliers (weight < 0),
// which mrcal respects.
void AddBoardObservations(const std::vector<CalibrationView>& views,
                          const std::vector<Rigid3d>& seed_cam_from_target, MrcalProblem* problem) {
  const MrcalBoardSolve solve =
      MrcalBoardSolveOf(views, seed_cam_from_target, problem->grid, &problem->pool_to_point);
  const int num_frames = problem->num_frames;
  problem->pool.resize(static_cast<size_t>(num_frames) * problem->per_board);
  for (size_t k = 0; k < problem->pool.size(); ++k) {
    problem->pool[k] = {
        {solve.observations[3 * k], solve.observations[3 * k + 1], solve.observations[3 * k + 2]}};
  }
  problem->observations.resize(num_frames);
  problem->frames.resize(num_frames);
  for (int f = 0; f < num_frames; ++f) {
    problem->observations[f].icam.intrinsics = 0;
    problem->observations[f].icam.extrinsics = -1;  // the camera is the reference
    problem->observations[f].iframe = f;
    for (int i = 0; i < 3; ++i) {
      problem->frames[f].r.xyz[i] = solve.frames_rt_toref[f][i];
      problem->frames[f].t.xyz[i] = solve.frames_rt_toref[f][3 + i];
    }
  }
  problem->missing.resize(problem->pool.size());
  for (size_t k = 0; k < problem->pool.size(); ++k) {
    problem->missing[k] = problem->pool[k].z < 0;
    if (!problem->missing[k]) ++problem->num_points;
  }
}

// J^T J of mrcal's (packed, unitless) state at the solution, J including
// the regularisation terms; `x` gets the measurements.
Eigen::MatrixXd MrcalJtJ(MrcalProblem* pr, std::vector<double>* x) {
  const int num_frames = pr->num_frames;
  const int num_state =
      mrcal_num_states(1, 0, num_frames, 0, 0, num_frames, pr->selections, &pr->lensmodel);
  const int num_meas = mrcal_num_measurements(num_frames, 0, pr->grid.width_n, pr->grid.height_n, 1,
                                              0, num_frames, 0, 0, pr->selections, &pr->lensmodel);
  const int num_nonzero =
      _mrcal_num_j_nonzero(num_frames, 0, pr->grid.width_n, pr->grid.height_n, 1, 0, num_frames, 0,
                           0, pr->observations.data(), nullptr, pr->selections, &pr->lensmodel);
  std::vector<double> b_packed(num_state), jt_x(num_nonzero);
  x->assign(num_meas, 0.0);
  std::vector<int> jt_p(num_meas + 1), jt_i(num_nonzero);
  cholmod_sparse jt = {};
  jt.nrow = num_state;
  jt.ncol = num_meas;
  jt.nzmax = num_nonzero;
  jt.p = jt_p.data();
  jt.i = jt_i.data();
  jt.x = jt_x.data();
  jt.stype = 0;
  jt.itype = CHOLMOD_INT;
  jt.xtype = CHOLMOD_REAL;
  jt.dtype = CHOLMOD_DOUBLE;
  jt.sorted = 1;
  jt.packed = 1;
  if (!mrcal_optimizer_callback(
          b_packed.data(), num_state * static_cast<int>(sizeof(double)), x->data(),
          num_meas * static_cast<int>(sizeof(double)),
          reinterpret_cast<cholmod_sparse_struct*>(&jt), pr->intrinsics.data(), nullptr,
          pr->frames.data(), nullptr, &pr->warp, 1, 0, num_frames, 0, 0, pr->observations.data(),
          nullptr, num_frames, 0, pr->pool.data(), &pr->lensmodel, pr->imagersize, pr->selections,
          &pr->constants, pr->grid.spacing, pr->grid.width_n, pr->grid.height_n, false)) {
    throw NumericalError("mrcal_optimizer_callback failed (its message is above)");
  }
  Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(num_state, num_state);
  for (int m = 0; m < num_meas; ++m) {
    for (int a = jt_p[m]; a < jt_p[m + 1]; ++a) {
      for (int b = jt_p[m]; b < jt_p[m + 1]; ++b) {
        jtj(jt_i[a], jt_i[b]) += jt_x[a] * jt_x[b];
      }
    }
  }
  return jtj;
}

// Covariance as mrcal's uncertainty model has it: Var(b) = s^2 (J^T J)^-1
// over the packed state, s^2 the residual variance of the inlier corners;
// then unpacked to units.
void FillMrcalCovariance(MrcalProblem* pr, bool estimate_board_warp,
                         MrcalCalibrationResult* result) {
  std::vector<double> x;
  const Eigen::MatrixXd jtj = MrcalJtJ(pr, &x);
  const int num_state = static_cast<int>(jtj.rows());
  const int num_frames = pr->num_frames;
  const int num_intrinsics = static_cast<int>(pr->intrinsics.size());
  // Inlier corner residuals: the first 2 * (H * W) * frames measurements.
  double sum_squares = 0;
  int num_inliers = 0;
  for (size_t k = 0; k < pr->pool.size(); ++k) {
    if (pr->pool[k].z < 0) continue;
    sum_squares += x[2 * k] * x[2 * k] + x[2 * k + 1] * x[2 * k + 1];
    ++num_inliers;
  }
  result->rms_px = std::sqrt(sum_squares / std::max(1, num_inliers));
  const int dof = 2 * num_inliers - num_state;
  const double variance = dof > 0 ? sum_squares / dof : 0;
  result->residual_sigma_px = std::sqrt(variance);

  std::vector<double> unpack(num_state, 1.0);
  mrcal_unpack_solver_state_vector(unpack.data(), 1, 0, num_frames, 0, 0, pr->selections,
                                   &pr->lensmodel);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
  result->params_covariance = Eigen::MatrixXd::Zero(num_intrinsics, num_intrinsics);
  result->params_std_dev.assign(num_intrinsics, 0.0);
  if (!(ldlt.info() == Eigen::Success && ldlt.isPositive())) {
    LOG(WARNING) << "mrcal: J^T J is singular; no standard deviations";
    return;
  }
  const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(num_state, num_state));
  const int i0 = mrcal_state_index_intrinsics(0, 1, 0, num_frames, 0, 0, num_frames, pr->selections,
                                              &pr->lensmodel);
  for (int a = 0; a < num_intrinsics; ++a) {
    for (int b = 0; b < num_intrinsics; ++b) {
      result->params_covariance(a, b) =
          inverse(i0 + a, i0 + b) * unpack[i0 + a] * unpack[i0 + b] * variance;
    }
    result->params_std_dev[a] = std::sqrt(std::max(0.0, result->params_covariance(a, a)));
  }
  if (estimate_board_warp) {
    const int w0 = mrcal_state_index_calobject_warp(1, 0, num_frames, 0, 0, num_frames,
                                                    pr->selections, &pr->lensmodel);
    for (int a = 0; a < 2; ++a) {
      result->board_warp_std_dev[a] =
          std::sqrt(std::max(0.0, inverse(w0 + a, w0 + a) * variance)) * unpack[w0 + a];
    }
  }
}

}  // namespace

MrcalCalibrationResult CalibrateWithMrcal(const std::vector<CalibrationView>& views,
                                          const Camera& seed,
                                          const std::vector<Rigid3d>& seed_cam_from_target,
                                          const MrcalCalibrationOptions& options) {
  options.Check();
  PORTCAL_CHECK(views.size() == seed_cam_from_target.size());
  MrcalProblem pr;
  pr.grid = InferBoardGrid(views);
  const MrcalLens seed_lens = MrcalLensFromCamera(seed);
  PORTCAL_CHECK(mrcal_lensmodel_from_name(&pr.lensmodel, seed_lens.lensmodel.c_str()));
  PORTCAL_CHECK(mrcal_lensmodel_num_params(&pr.lensmodel) ==
                static_cast<int>(seed_lens.intrinsics.size()));
  pr.num_frames = static_cast<int>(views.size());
  pr.per_board = pr.grid.width_n * pr.grid.height_n;
  AddBoardObservations(views, seed_cam_from_target, &pr);
  pr.intrinsics = seed_lens.intrinsics;
  pr.imagersize[0] = static_cast<int>(seed.width);
  pr.imagersize[1] = static_cast<int>(seed.height);
  pr.selections.do_optimize_intrinsics_core = true;
  pr.selections.do_optimize_intrinsics_distortions = true;
  pr.selections.do_optimize_extrinsics = false;
  pr.selections.do_optimize_frames = true;
  pr.selections.do_optimize_calobject_warp = options.estimate_board_warp;
  pr.selections.do_apply_regularization = options.regularization;
  pr.selections.do_apply_outlier_rejection = options.reject_outliers;

  const mrcal_stats_t stats = mrcal_optimize(
      nullptr, 0, nullptr, 0, pr.intrinsics.data(), nullptr, pr.frames.data(), nullptr, &pr.warp, 1,
      0, pr.num_frames, 0, 0, pr.observations.data(), nullptr, pr.num_frames, 0, pr.pool.data(),
      &pr.lensmodel, pr.imagersize, pr.selections, &pr.constants, pr.grid.spacing, pr.grid.width_n,
      pr.grid.height_n, options.verbose, false);
  if (!std::isfinite(stats.rms_reproj_error__pixels) || stats.rms_reproj_error__pixels < 0) {
    throw NumericalError("mrcal_optimize failed (its message is above)");
  }

  MrcalCalibrationResult result;
  result.lensmodel = seed_lens.lensmodel;
  result.camera = CameraFromMrcalLens({seed_lens.lensmodel, pr.intrinsics}, seed.width, seed.height,
                                      "mrcal's solution");
  result.board_warp = Eigen::Vector2d(pr.warp.x2, pr.warp.y2);
  result.num_points = pr.num_points;
  result.outliers.resize(pr.num_frames);
  for (int f = 0; f < pr.num_frames; ++f) {
    for (int k = 0; k < pr.per_board; ++k) {
      if (pr.pool[f * pr.per_board + k].z < 0 && !pr.missing[f * pr.per_board + k]) {
        result.outliers[f].push_back(pr.pool_to_point[f][k]);
        ++result.num_outliers;
      }
    }
  }
  FillMrcalCovariance(&pr, options.estimate_board_warp, &result);
  LOG(INFO) << "mrcal (" << result.lensmodel << "): RMS " << result.rms_px << " px, "
            << result.num_outliers << " of " << pr.num_points << " corners rejected, board warp ("
            << result.board_warp.x() * 1e3 << ", " << result.board_warp.y() * 1e3 << ") mm";
  return result;
}

}  // namespace portcal
