// Sub-pixel chessboard corners by fitting the ideal corner pattern.
//
// Around an inner corner a chessboard image is two straight edges crossing,
// dark and light quadrants alternating, blurred by optics and pixel area.
// The model
//   I(p) = m + a * erf(s1 / (sqrt(2) sigma)) * erf(s2 / (sqrt(2) sigma)),
//   s_k = n_k . (p - c),  n_k = (cos theta_k, sin theta_k)
// integrated over each pixel's area, is point-symmetric about the corner c,
// as the pattern is, so a mismatch in the edge profile does not bias c. It
// is fitted to the pixels of a window by Levenberg-Marquardt (a fixed-size
// solver with the model's derivatives written out,
// colmap_ext/cost/corner_pattern_model.h): c, both edge angles (any
// perspective), the levels m, a and the blur sigma. Compared with the
// gradient-orthogonality of cv::cornerSubPix it uses the whole edge profile
// and does not assume orthogonal edges.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace portcal {

struct CornerRefinementOptions {
  // Window half size as a fraction of the distance to the nearest
  // neighbouring corner, clamped to [min, max] pixels. A smaller maximum
  // (10 px) was faster, but its noisy corners made the intrinsics' standard
  // deviations optimistic (CalibrationUncertainty, docs/benchmarks_target_detection.md).
  double window_fraction = 0.4;
  double min_window_px = 3;
  double max_window_px = 15;
  // A refined corner further than this from its start is rejected; in a
  // grid, further than this or the fraction of the distance to the nearest
  // neighbouring corner, whichever is larger (the coarse corners of a
  // blurred view can be pixels off; the next junction is a square away).
  double max_shift_px = 2.0;
  double max_shift_fraction = 0.15;
  int max_num_iterations = 50;
  // The fit stops once a step moves the corner by less than this (or the
  // cost by less than 1e-6 of itself).
  double corner_tolerance_px = 2e-4;
  // A grid's corners are fitted again with each window's pixels brought to
  // the corner's own levels (board_shading.h) where the board's levels
  // drift by more than this fraction of the contrast over the window (0:
  // wherever they drift at all; < 0: never).
  double max_level_drift = 0.002;
  void Check() const;  // throws OptionError
};

struct RefinedCorner {
  Eigen::Vector2d xy;    // COLMAP pixels
  double rms_gray = 0;   // fit residual, gray levels
  double contrast = 0;   // |a| * 2, gray levels
  double mean_gray = 0;  // m
  double blur_sigma_px = 0;
};

// Why a corner was not refined.
enum class CornerFailure {
  kNone,
  kNearImageBorder,
  kNoContrast,
  kDiverged,
  kMovedTooFar,
  kNotSeen
};
const char* CornerFailureText(CornerFailure failure);  // e.g. "no contrast"

// Refines one corner from `start` (COLMAP pixels) with a circular window of
// `half_window_px` and initial edge-normal angles (radians). nullopt when the
// fit fails, with the reason in *failure if given.
std::optional<RefinedCorner> RefineCorner(const cv::Mat& gray, const Eigen::Vector2d& start,
                                          double half_window_px, double normal_angle1,
                                          double normal_angle2,
                                          const CornerRefinementOptions& options,
                                          CornerFailure* failure = nullptr);

// Where a board's corner starts its fit from.
struct CornerStart {
  Eigen::Vector2d xy;  // COLMAP pixels
  double half_window_px = 8;
  double normal_angle1 = 0, normal_angle2 = 0;  // the two edges' normals, radians
  double max_shift_px = 2;
  bool seen = true;  // false: not fitted (kNotSeen)
};

// Refines the corners of one board, each from its start: fitted once, the
// board's shading fitted over them (board_shading.h), and fitted again
// where the levels drift across a window by more than `max_level_drift`,
// with the window brought to the corner's own levels. nullopt for corners
// whose fit failed, with the reasons in *failures if given.
std::vector<std::optional<RefinedCorner>> RefineBoardCorners(
    const cv::Mat& gray, const std::vector<CornerStart>& starts,
    const CornerRefinementOptions& options = {}, std::vector<CornerFailure>* failures = nullptr);

// Refines corners (COLMAP pixel convention) of a grid of rows x cols inner
// corners, index r * cols + c, in an 8-bit gray image. nullopt for corners
// whose fit failed (no contrast, diverged, moved too far), with the reasons
// in *failures (one per corner, kNone where refined) if given. The corners
// are fitted twice where the board's levels drift across the windows
// (`max_level_drift`). With `seen`, only the corners it marks are fitted
// (the others, of a board in part out of view, are kNotSeen; their
// positions still set their neighbours' windows and edge directions).
std::vector<std::optional<RefinedCorner>> RefineChessboardCorners(
    const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols, int rows,
    const CornerRefinementOptions& options = {}, std::vector<CornerFailure>* failures = nullptr,
    const std::vector<bool>* seen = nullptr);

}  // namespace portcal
