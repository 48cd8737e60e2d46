#include "pipelines/crosscheck/mrcal_import.h"

#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

// target_extractor's description of the chessboard mrcal saw (its corners
// are a chessboard's inner corners: mrgingham's, or portcal's own).
std::string ChessboardDescription(const MrcalBoardSolve& solve) {
  std::ostringstream out;
  out << "chessboard " << solve.width_n << "x" << solve.height_n << " inner corners, square "
      << solve.spacing << " m";
  return out.str();
}

}  // namespace

InAirViews InAirViewsOfMrcalSolve(const MrcalBoardSolve& solve, const Camera& camera,
                                  const std::string& underwater_target, const std::string& context,
                                  bool share_board_warp) {
  InAirViews in_air;
  const int per_board = solve.width_n * solve.height_n;
  for (size_t f = 0; f < solve.frames_rt_toref.size(); ++f) {
    CalibrationView view;
    view.image_name =
        f < solve.image_paths.size() ? solve.image_paths[f] : "frame " + std::to_string(f);
    for (int k = 0; k < per_board; ++k) {
      const double* corner = &solve.observations[(f * per_board + k) * 3];
      if (!(corner[2] > 0)) continue;
      // mrcal's board frame: corner (row, col) at (col, row) x spacing, z = 0.
      view.points_in_target.emplace_back((k % solve.width_n) * solve.spacing,
                                         (k / solve.width_n) * solve.spacing, 0);
      view.pixels.emplace_back(corner[0] + 0.5, corner[1] + 0.5);  // mrcal's pixels -> COLMAP's
    }
    if (view.pixels.size() >= 4) in_air.views.push_back(std::move(view));
  }
  if (in_air.views.empty()) throw InputError(context + ": no view in its solve keeps 4 corners");
  in_air.share_board_warp = share_board_warp && underwater_target == ChessboardDescription(solve);
  // mrcal's core is fx, fy, cx, cy: the first four parameters of the models
  // a .cameramodel reads as (PINHOLE, OPENCV, FULL_OPENCV); the rest are
  // the distortions.
  PORTCAL_CHECK(CameraModelFocalLengthIdxs(camera.model_id).size() == 2);
  const int num_core = 4;
  for (int i = 0; i < static_cast<int>(camera.params.size()); ++i) {
    if ((i < num_core && !solve.intrinsics_core_estimated) ||
        (i >= num_core && !solve.intrinsics_distortions_estimated)) {
      in_air.fixed_params.push_back(i);
    }
  }
  return in_air;
}

}  // namespace portcal
