#include "pipelines/markers/marker_edge_refinement.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "colmap_ext/cost/erf_pixel_average.h"

namespace portcal {
namespace {

// A side's edge in the frame of its first corner: offset along the outward
// normal as a quadratic in the distance along the side. Lens distortion and
// refraction at a port bend straight edges; the quadratic follows the bend
// so that the corners, extrapolated to the ends, stay unbiased on large
// markers.
struct EdgeCurve {
  Eigen::Vector2d origin, u, n;
  Eigen::Vector3d coefficients = Eigen::Vector3d::Zero();  // d(t) = c0 + c1 t + c2 t^2
  Eigen::Vector2d Point(double t) const {
    return origin + t * u + (coefficients(0) + t * (coefficients(1) + t * coefficients(2))) * n;
  }
  Eigen::Vector2d Tangent(double t) const {
    return (u + (coefficients(1) + 2 * t * coefficients(2)) * n).normalized();
  }
};

std::optional<Eigen::Vector2d> IntersectLines(const Eigen::Vector2d& pa, const Eigen::Vector2d& da,
                                              const Eigen::Vector2d& pb, const Eigen::Vector2d& db) {
  Eigen::Matrix2d A;
  A << da, -db;
  if (std::abs(A.determinant()) < 1e-6) return std::nullopt;
  const Eigen::Vector2d t = A.colPivHouseholderQr().solve(pb - pa);
  return pa + t(0) * da;
}

// Where the end of `before` meets the start of `after`: tangent lines at
// the current estimates, intersected, a few times over.
std::optional<Eigen::Vector2d> IntersectCurves(const EdgeCurve& before, double before_length,
                                               const EdgeCurve& after) {
  double t1 = before_length, t2 = 0;
  std::optional<Eigen::Vector2d> x;
  for (int iteration = 0; iteration < 5; ++iteration) {
    x = IntersectLines(before.Point(t1), before.Tangent(t1), after.Point(t2), after.Tangent(t2));
    if (!x) return std::nullopt;
    t1 = (*x - before.origin).dot(before.u);
    t2 = (*x - after.origin).dot(after.u);
  }
  return x;
}

struct BandPixel {
  double t, s, gray;  // along the side (over its length), along the outward normal, gray
};

// The pixels whose centres lie within `half_width` of the side and away
// from its ends (empty where the band leaves the image).
std::vector<BandPixel> CollectBand(const cv::Mat& gray, const Eigen::Vector2d& a, const Eigen::Vector2d& u,
                                   const Eigen::Vector2d& n, double length, double half_width, double end_margin) {
  std::vector<BandPixel> band;
  const Eigen::Vector2d b = a + length * u;
  const double reach = half_width + 1;
  const int x0 = static_cast<int>(std::floor(std::min(a.x(), b.x()) - reach));
  const int x1 = static_cast<int>(std::ceil(std::max(a.x(), b.x()) + reach));
  const int y0 = static_cast<int>(std::floor(std::min(a.y(), b.y()) - reach));
  const int y1 = static_cast<int>(std::ceil(std::max(a.y(), b.y()) + reach));
  if (x0 < 0 || y0 < 0 || x1 >= gray.cols || y1 >= gray.rows) return band;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d p(x, y);  // OpenCV pixels: the pixel's centre
      const double t = (p - a).dot(u), s = (p - a).dot(n);
      if (t < end_margin * length || t > (1 - end_margin) * length || std::abs(s) > half_width) continue;
      band.push_back({t / length, s, static_cast<double>(gray.at<uint8_t>(y, x))});
    }
  }
  return band;
}

// The side's edge fitted to the pixels of a band along it: each pixel's gray
// is m + k * (the mean over the pixel of erf(u)), u = (s - d(t)) / (sqrt(2)
// sigma), s the pixel centre's offset along the outward normal, t along
// the side and d(t) the edge's offset (quadratic for a long side). The
// pixel's area is integrated in closed form (erf_pixel_average.h), the
// blur fitted: no level is read off a profile's ends, which a blur that
// reaches the next module would shift. Levenberg-Marquardt with the
// derivatives written out. Returns d's coefficients in t (pixels).
std::optional<Eigen::Vector3d> FitEdgeToPixels(const cv::Mat& gray, const Eigen::Vector2d& a, const Eigen::Vector2d& u,
                                               const Eigen::Vector2d& n, double length, double half_width,
                                               double end_margin, bool quadratic, double min_contrast) {
  const std::vector<BandPixel> band = CollectBand(gray, a, u, n, length, half_width, end_margin);
  if (band.size() < 20) return std::nullopt;
  // q: c0, c1, c2, m, k, log sigma.
  Eigen::Matrix<double, 6, 1> q;
  double dark = 0, light = 0;
  int num_dark = 0, num_light = 0;
  for (const BandPixel& p : band) {
    if (p.s < -0.5 * half_width) {
      dark += p.gray;
      ++num_dark;
    } else if (p.s > 0.5 * half_width) {
      light += p.gray;
      ++num_light;
    }
  }
  if (num_dark == 0 || num_light == 0) return std::nullopt;
  dark /= num_dark;
  light /= num_light;
  if (light - dark < min_contrast) return std::nullopt;
  q << 0, 0, 0, 0.5 * (dark + light), 0.5 * (light - dark), std::log(0.8);
  const auto linearise = [&](const Eigen::Matrix<double, 6, 1>& at, Eigen::Matrix<double, 6, 6>* jtj,
                             Eigen::Matrix<double, 6, 1>* jtr) {
    const double w = std::exp(-at[5]) / std::sqrt(2.0);
    const double width_x = w * n.x(), width_y = w * n.y();
    jtj->setZero();
    jtr->setZero();
    double cost = 0;
    for (const BandPixel& p : band) {
      const double d = at[0] + p.t * (at[1] + p.t * at[2]);
      const double u0 = (p.s - d) * w;
      const ErfPixelAverage m = AverageErfOverPixel(u0, width_x, width_y);
      const double r = at[3] + at[4] * m.value - p.gray;
      Eigen::Matrix<double, 6, 1> g;
      const double d_d = -at[4] * m.d_u0 * w;  // d value / d d
      g << d_d, d_d * p.t, quadratic ? d_d * p.t * p.t : 0.0, 1.0, m.value,
          -at[4] * (m.d_u0 * u0 + m.d_a * width_x + m.d_b * width_y);
      jtj->selfadjointView<Eigen::Lower>().rankUpdate(g);
      *jtr += r * g;
      cost += 0.5 * r * r;
    }
    *jtj = jtj->selfadjointView<Eigen::Lower>();
    if (!quadratic) (*jtj)(2, 2) = 1;  // c2 stays 0
    return cost;
  };
  Eigen::Matrix<double, 6, 6> jtj;
  Eigen::Matrix<double, 6, 1> jtr;
  double cost = linearise(q, &jtj, &jtr);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Matrix<double, 6, 6> damped = jtj;
    damped.diagonal() *= 1 + lambda;
    const Eigen::Matrix<double, 6, 1> step = damped.ldlt().solve(-jtr);
    if (!step.allFinite()) return std::nullopt;
    Eigen::Matrix<double, 6, 6> trial_jtj;
    Eigen::Matrix<double, 6, 1> trial_jtr;
    const double trial_cost = linearise(q + step, &trial_jtj, &trial_jtr);
    if (std::isfinite(trial_cost) && trial_cost < cost) {
      q += step;
      const bool converged = cost - trial_cost < 1e-9 * cost || std::abs(step[0]) < 1e-5;
      cost = trial_cost;
      jtj = trial_jtj;
      jtr = trial_jtr;
      lambda = std::max(1e-9, lambda / 3);
      if (converged) break;
    } else {
      lambda *= 4;
      if (lambda > 1e8) break;
    }
  }
  if (!q.allFinite() || q[4] * 2 < min_contrast) return std::nullopt;
  return Eigen::Vector3d(q[0], q[1] / length, q[2] / (length * length));
}

}  // namespace

bool RefineMarkerCorners(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                         std::array<cv::Point2d, 4>* corners) {
  std::array<Eigen::Vector2d, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = Eigen::Vector2d((*corners)[i].x, (*corners)[i].y);
  const Eigen::Vector2d centroid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  std::array<EdgeCurve, 4> curves;
  std::array<double, 4> lengths;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = c[i], b = c[(i + 1) % 4];
    const double length = (b - a).norm();
    if (length < 8) return false;
    const Eigen::Vector2d u = (b - a) / length;
    Eigen::Vector2d n(-u.y(), u.x());
    if (n.dot(0.5 * (a + b) - centroid) < 0) n = -n;  // outward
    // Stay within the black border module inside and the light module
    // outside.
    const double module = length / (options.bits_per_side + 2);
    const double half_width = std::clamp(0.45 * module, 1.5, 6.0);
    // A bend needs a long side to be measured; short sides are lines.
    const auto fit = FitEdgeToPixels(gray, a, u, n, length, half_width, options.end_margin, length >= 40,
                                     options.min_contrast);
    if (!fit) return false;
    curves[i] = EdgeCurve{a, u, n, *fit};
    lengths[i] = length;
  }
  // OpenCV's corner of a small, oblique marker can be pixels off; allow a
  // tenth of the side.
  const double max_shift =
      std::max(options.max_corner_shift_px, 0.025 * (lengths[0] + lengths[1] + lengths[2] + lengths[3]));
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
