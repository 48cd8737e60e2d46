// A camera's in-air board views taken back from an mrcal .cameramodel's
// optimization_inputs (mrcal-calibrate-cameras' or portcal's), so that a
// housing's joint solve can use them when the .cameramodel is all a user
// kept of the in-air calibration.
#pragma once

#include <string>

#include "colmap_ext/io/mrcal_model.h"
#include "pipelines/calibration/housing_calibration.h"

namespace portcal {

// The views of `solve` (ReadMrcalBoardSolve), corners with weight <= 0
// left out (mrcal's outliers and missing corners), in COLMAP pixels; the
// intrinsics mrcal held (by group: the core fx, fy, cx, cy, or the
// distortions) held, as indices into `camera`'s parameters. The board
// warp is shared (`share_board_warp`) only when asked and
// `underwater_target` (target_extractor's description) is the same
// chessboard. mrcal's per-corner weights (mrgingham's decimation levels)
// are not carried: each kept corner counts once. Throws InputError naming
// `context` when fewer than 4 corners remain in every view.
InAirViews InAirViewsOfMrcalSolve(const MrcalBoardSolve& solve, const Camera& camera,
                                  const std::string& underwater_target, const std::string& context,
                                  bool share_board_warp = false);

}  // namespace portcal
