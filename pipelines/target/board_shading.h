// How the gray levels of a board vary across the image: vignetting, the
// light's fall-off, water's attenuation with distance and its veil make the
// light and dark squares' levels drift by percents across a corner's window
// at the image's rim. The corner model's levels are constant over a window,
// so such a drift pulls the fitted corner towards or away from the brighter
// side (median 0.0073 -> 0.012 px on renders with 50 % vignetting;
// docs/benchmarks_target_detection.md). Fitting a trend per corner costs every corner two
// more free parameters, and clean views lose accuracy with them; instead
// the mean level and the contrast are fitted as smooth fields over the
// whole board, from every corner's first fit, and each window's pixels are
// brought to the corner's own levels before the second fit.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <optional>
#include <vector>

namespace portcal {

// The levels about one point: I(p) ~ mean + mean_gradient . d +
// (1 + relative_contrast_gradient . d) * contrast * pattern(p), d = p - point.
struct LocalShading {
  double mean = 0;
  Eigen::Vector2d mean_gradient = Eigen::Vector2d::Zero();               // gray levels per pixel
  Eigen::Vector2d relative_contrast_gradient = Eigen::Vector2d::Zero();  // per pixel

  // The gray at `offset` from the point brought to the point's levels.
  double Flatten(double gray, const Eigen::Vector2d& offset) const {
    return mean +
           (gray - mean - mean_gradient.dot(offset)) / (1 + relative_contrast_gradient.dot(offset));
  }
  // How far the levels drift over `radius` pixels, as a fraction of the
  // contrast `contrast` (the larger of the two).
  double Drift(double radius, double contrast) const {
    return radius * std::max(mean_gradient.norm() / contrast, relative_contrast_gradient.norm());
  }
};

// Quadratic fields (linear with fewer than 12 corners) of the corners'
// mean level and log contrast over the image, least squares, once more
// without corners beyond 3 robust sigmas. nullopt with fewer than 6.
class BoardShading {
 public:
  static std::optional<BoardShading> Fit(const std::vector<Eigen::Vector2d>& corners,
                                         const std::vector<double>& means,
                                         const std::vector<double>& contrasts);
  LocalShading At(const Eigen::Vector2d& point) const;

 private:
  Eigen::VectorXd Basis(const Eigen::Vector2d& point) const;
  Eigen::MatrixXd BasisGradient(const Eigen::Vector2d& point) const;  // 2 x terms

  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double scale_ = 1;  // pixels per unit of the fields' coordinates
  int num_terms_ = 3;
  Eigen::VectorXd mean_, log_contrast_;
};

}  // namespace portcal
