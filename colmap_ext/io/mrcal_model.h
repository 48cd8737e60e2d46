// COLMAP camera models <-> mrcal lens models (mrcal 2.2), and mrcal's
// .cameramodel files (read by mrcal's own C parser).
//
// The two sides differ in the pixel convention only: mrcal (like OpenCV)
// puts the centre of the top-left pixel at (0, 0), COLMAP at (0.5, 0.5), so
// cx, cy move by 0.5 px; the projection formulas of OPENCV / FULL_OPENCV and
// LENSMODEL_OPENCV4 / LENSMODEL_OPENCV8 are the same (OpenCV's), with the
// parameters in the same order (fx, fy, cx, cy, k1, k2, p1, p2[, k3..k6]).
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct MrcalLens {
  std::string lensmodel;           // e.g. "LENSMODEL_OPENCV4"
  std::vector<double> intrinsics;  // mrcal's order and pixel convention
};

// The mrcal model that expresses `colmap_model` exactly (SIMPLE_PINHOLE and
// PINHOLE -> LENSMODEL_PINHOLE; SIMPLE_RADIAL, RADIAL and OPENCV ->
// LENSMODEL_OPENCV4; FULL_OPENCV -> LENSMODEL_OPENCV8). Throws InputError
// naming the nearest mrcal model for the others (fisheye, FOV, thin prism).
std::string MrcalLensModelFor(const std::string& colmap_model);

// What mrcal frees that the COLMAP model ties (fx = fy, p1 = p2 = 0, ...),
// as text for reports; empty when the two are the same parameterisation.
std::string MrcalExtraFreedom(const std::string& colmap_model);

// For each of mrcal's intrinsics (in mrcal's order), the index of the COLMAP
// parameter it equals, or -1 where the COLMAP model holds it at 0 (e.g.
// RADIAL -> OPENCV4: {0, 0, 1, 2, 3, 4, -1, -1}). Also maps standard
// deviations and covariances. Throws like MrcalLensModelFor.
std::vector<int> MrcalParamSources(const std::string& colmap_model);

// Exact conversions. MrcalLensFromCamera throws like MrcalLensModelFor;
// CameraFromMrcalLens maps LENSMODEL_PINHOLE -> PINHOLE, OPENCV4 -> OPENCV,
// OPENCV5 and OPENCV8 -> FULL_OPENCV, and throws InputError (prefixed by
// `context`) for models COLMAP cannot express.
MrcalLens MrcalLensFromCamera(const Camera& camera);
Camera CameraFromMrcalLens(const MrcalLens& lens, uint64_t width, uint64_t height,
                           const std::string& context);

// Per-parameter standard deviations and covariances carry over unchanged
// (the pixel shift is a constant), in the order of the respective model.

// What mrcal's uncertainty and diagnostic tools (mrcal-show-projection-
// uncertainty, mrcal-show-residuals-board-observation, ...) re-evaluate: a
// single camera's board solve, as mrcal.optimize() takes it. The lens is
// the camera's own (intrinsics, lensmodel, imagersizes are filled from it);
// the camera is the reference frame.
struct MrcalBoardSolve {
  int width_n = 0;  // corners per row and column, `spacing` apart
  int height_n = 0;
  double spacing = 0;  // metres
  // Per board observation: rt_ref_board (Rodrigues, translation; the board
  // frame at corner (0, 0)) and the (height_n, width_n) corners as (x, y,
  // weight) in mrcal's pixels (top-left pixel's centre at (0, 0)), weight < 0
  // for a corner that was not used.
  std::vector<std::array<double, 6>> frames_rt_toref;
  std::vector<double> observations;
  std::vector<std::string> image_paths;
  Eigen::Vector2d calobject_warp = Eigen::Vector2d::Zero();  // metres
  bool warp_estimated = false;
  bool intrinsics_core_estimated = true;         // fx, fy, cx, cy
  bool intrinsics_distortions_estimated = true;  // the rest
};

struct MrcalCameraModelFile {
  Camera camera;
  Rigid3d cam_from_ref;  // mrcal's "extrinsics" (rt_cam_ref)
  // The solve the model came from, as stored (base 85 of an .npz archive;
  // empty when the file has none), and which of its cameras this is.
  // Decoded by ReadMrcalBoardSolve (mrcal_optimization_inputs.h) only
  // where wanted: a damaged solve does not stop the lens being read.
  std::string optimization_inputs_base85;
  int icam_intrinsics = -1;
};

// mrcal's pose vector of b_from_a: Rodrigues rotation, then translation.
std::array<double, 6> RtFromRigid(const Rigid3d& b_from_a);
Rigid3d RigidFromRt(const double* rt);

// Reads a .cameramodel with mrcal's parser. Throws InputError naming the file.
MrcalCameraModelFile ReadMrcalCameraModel(const std::filesystem::path& path);
// Writes at full precision (mrcal's writer keeps 6 decimals), atomically;
// with `solve`, also its optimization_inputs (regularisation and outlier
// rejection off: portcal's solution has neither) and icam_intrinsics 0.
void WriteMrcalCameraModel(const Camera& camera, const Rigid3d& cam_from_ref,
                           const std::filesystem::path& path,
                           const MrcalBoardSolve* solve = nullptr);

}  // namespace portcal
