#include "pipelines/markers/marker_edge_crossings.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "pipelines/markers/edge_curve.h"

namespace portcal {
namespace {

// Bilinear sample; nullopt outside the image.
std::optional<double> Sample(const cv::Mat& gray, const Eigen::Vector2d& p) {
  const double x = p.x(), y = p.y();
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= gray.cols || y0 + 1 >= gray.rows) return std::nullopt;
  const double fx = x - x0, fy = y - y0;
  const auto v = [&](int r, int c) { return static_cast<double>(gray.at<uint8_t>(r, c)); };
  return (1 - fy) * ((1 - fx) * v(y0, x0) + fx * v(y0, x0 + 1)) +
         fy * ((1 - fx) * v(y0 + 1, x0) + fx * v(y0 + 1, x0 + 1));
}

// Least squares with one pass dropping points beyond 3x the median
// residual (a bit edge or a specular spot).
std::optional<Eigen::Vector3d> FitEdge(std::vector<Eigen::Vector2d> td, bool quadratic) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    if (td.size() < (quadratic ? 10u : 5u)) return std::nullopt;
    const int k = quadratic ? 3 : 2;
    Eigen::MatrixXd A(td.size(), k);
    Eigen::VectorXd b(td.size());
    for (size_t i = 0; i < td.size(); ++i) {
      A(i, 0) = 1;
      A(i, 1) = td[i].x();
      if (quadratic) A(i, 2) = td[i].x() * td[i].x();
      b(i) = td[i].y();
    }
    const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);
    c.setZero();
    c.head(k) = x;
    if (pass == 1) break;
    std::vector<double> residuals;
    for (size_t i = 0; i < td.size(); ++i) residuals.push_back(std::abs((A.row(i) * x)(0) - b(i)));
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = std::max(0.05, 3.0 * sorted[sorted.size() / 2]);
    std::vector<Eigen::Vector2d> kept;
    for (size_t i = 0; i < td.size(); ++i) {
      if (residuals[i] <= limit) kept.push_back(td[i]);
    }
    td.swap(kept);
  }
  return c;
}

}  // namespace

bool RefineMarkerCornersByCrossings(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                                    std::array<cv::Point2d, 4>* corners) {
  std::array<Eigen::Vector2d, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = Eigen::Vector2d((*corners)[i].x, (*corners)[i].y);
  std::array<EdgeCurve, 4> curves;
  std::array<double, 4> lengths;
  for (int i = 0; i < 4; ++i) {
    const QuadSide side = SideOfQuad(c, i);
    const Eigen::Vector2d a = side.a, u = side.u, n = side.n;
    const double length = side.length;
    if (length < 8) return false;
    // Stay within the black border module inside and the light module
    // outside.
    const double module = length / (options.bits_per_side + 2);
    const double half_width = std::clamp(0.45 * module, 1.5, 6.0);
    constexpr double kStep = 0.05;
    std::vector<Eigen::Vector2d> edge;  // (t along the side, offset along n)
    for (double t = options.end_margin * length; t <= (1 - options.end_margin) * length; t += 0.5) {
      const Eigen::Vector2d p = a + t * u;
      std::vector<double> profile;
      bool inside_image = true;
      for (double s = -half_width; s <= half_width + 1e-9; s += kStep) {
        const auto v = Sample(gray, p + s * n);
        if (!v) {
          inside_image = false;
          break;
        }
        profile.push_back(*v);
      }
      if (!inside_image || profile.size() < 8) continue;
      const size_t k = std::max<size_t>(1, profile.size() / 8);
      double dark = 0, light = 0;
      for (size_t j = 0; j < k; ++j) {
        dark += profile[j];
        light += profile[profile.size() - 1 - j];
      }
      dark /= k;
      light /= k;
      if (light - dark < options.min_contrast) continue;
      const double mid = 0.5 * (dark + light);
      // The crossing nearest the predicted edge (s = 0).
      double best = 1e9;
      for (size_t j = 0; j + 1 < profile.size(); ++j) {
        if ((profile[j] - mid) * (profile[j + 1] - mid) > 0 || profile[j] == profile[j + 1])
          continue;
        const double s =
            -half_width + kStep * (j + (mid - profile[j]) / (profile[j + 1] - profile[j]));
        if (std::abs(s) < std::abs(best)) best = s;
      }
      if (best > 1e8) continue;
      edge.emplace_back(t, best);
    }
    // A bend needs a long side to be measured; short sides are lines.
    const auto fit = FitEdge(edge, length >= 40);
    if (!fit) return false;
    curves[i] = EdgeCurve{a, u, n, *fit};
    lengths[i] = length;
  }
  // OpenCV's corner of a small, oblique marker can be pixels off; allow a
  // tenth of the side.
  const double max_shift = std::max(options.max_corner_shift_px,
                                    0.025 * (lengths[0] + lengths[1] + lengths[2] + lengths[3]));
  std::array<cv::Point2d, 4> refined;
  for (int i = 0; i < 4; ++i) {
    // Corner i joins side i-1 (c[i-1] -> c[i]) and side i (c[i] -> c[i+1]).
    const int before = (i + 3) % 4;
    const auto x = IntersectCurves(curves[before], lengths[before], curves[i]);
    if (!x || (*x - c[i]).norm() > max_shift) return false;
    refined[i] = cv::Point2d(x->x(), x->y());
  }
  *corners = refined;
  return true;
}

}  // namespace portcal
