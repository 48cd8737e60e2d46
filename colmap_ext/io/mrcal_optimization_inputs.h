// mrcal's optimization_inputs (the keyword arguments of mrcal.optimize(),
// stored in a .cameramodel so that mrcal's tools can re-evaluate the solve):
// written for portcal's own board solves, and read back from any mrcal
// board calibration -- e.g. to use a camera's in-air views in a housing's
// joint solve when all one has is its .cameramodel.
#pragma once

#include <string>

#include "colmap_ext/io/mrcal_model.h"

namespace portcal {

// The .npz archive (not yet base 85) of `solve` for `camera` (as `lens`),
// regularisation and outlier rejection off: portcal's solution has neither.
std::string MrcalOptimizationInputsArchive(const MrcalLens& lens, const Camera& camera,
                                           const MrcalBoardSolve& solve);

// The board observations of `file`'s camera (its icam_intrinsics) in its
// optimization_inputs, as a one-camera solve: frames posed in that camera's
// frame (mrcal's reference frame composed with the camera's extrinsics in
// the solve), observations in mrcal's pixels with their weights (< 0 for a
// corner not used, e.g. an outlier mrcal rejected), what was optimised, the
// board warp, and the image paths when stored. `context` names the file in
// errors. Throws InputError when the file has no optimization_inputs, when
// they are malformed, or when its camera observed no board (a points-only
// solve).
MrcalBoardSolve ReadMrcalBoardSolve(const MrcalCameraModelFile& file, const std::string& context);

}  // namespace portcal
