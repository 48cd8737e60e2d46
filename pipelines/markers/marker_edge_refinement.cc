#include "pipelines/markers/marker_edge_refinement.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "pipelines/markers/edge_band_model.h"
#include "pipelines/markers/edge_curve.h"

namespace portcal {
namespace {

// The pixels whose centres lie within `half_width` of the side and away
// from its ends (empty where the band leaves the image).
std::vector<BandPixel> CollectBand(const cv::Mat& gray, const Eigen::Vector2d& a,
                                   const Eigen::Vector2d& u, const Eigen::Vector2d& n,
                                   double length, double half_width, double end_margin) {
  std::vector<BandPixel> band;
  const Eigen::Vector2d b = a + length * u;
  const double reach = half_width + 1;
  const int x0 = static_cast<int>(std::floor(std::min(a.x(), b.x()) - reach));
  const int x1 = static_cast<int>(std::ceil(std::max(a.x(), b.x()) + reach));
  const int y0 = static_cast<int>(std::floor(std::min(a.y(), b.y()) - reach));
  const int y1 = static_cast<int>(std::ceil(std::max(a.y(), b.y()) + reach));
  if (x0 < 0 || y0 < 0 || x1 >= gray.cols || y1 >= gray.rows) return band;
  for (int y = y0; y <= y1; ++y) {
    // The row's pixels within both slabs (|s| <= half_width, t inside the
    // margins): one interval, not the side's whole bounding box.
    double from = x0, to = x1;
    const auto clip = [&](const Eigen::Vector2d& direction, double lo, double hi) {
      const double offset = (y - a.y()) * direction.y() - a.x() * direction.x();  // value at x = 0
      if (std::abs(direction.x()) < 1e-12) {
        if (offset < lo || offset > hi) to = from - 1;
        return;
      }
      double x_lo = (lo - offset) / direction.x(), x_hi = (hi - offset) / direction.x();
      if (x_lo > x_hi) std::swap(x_lo, x_hi);
      from = std::max(from, x_lo);
      to = std::min(to, x_hi);
    };
    clip(n, -half_width, half_width);
    clip(u, end_margin * length, (1 - end_margin) * length);
    for (int x = static_cast<int>(std::ceil(from)); x <= static_cast<int>(std::floor(to)); ++x) {
      const Eigen::Vector2d p(x, y);  // OpenCV pixels: the pixel's centre
      const double t = (p - a).dot(u), s = (p - a).dot(n);
      if (t < end_margin * length || t > (1 - end_margin) * length || std::abs(s) > half_width)
        continue;
      band.push_back({t / length, s, static_cast<double>(gray.at<uint8_t>(y, x))});
    }
  }
  return band;
}

// Levenberg-Marquardt from `q`; false where a step is not finite.
bool MinimiseBand(const EdgeBandModel& model, const std::vector<BandPixel>& band,
                  const std::vector<char>& use, EdgeBandModel::Params* q) {
  EdgeBandModel::Normal jtj, trial_jtj;
  EdgeBandModel::Params jtr, trial_jtr;
  double cost = model.Linearise(band, use, *q, &jtj, &jtr);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 50; ++iteration) {
    EdgeBandModel::Normal damped = jtj;
    damped.diagonal() *= 1 + lambda;
    const EdgeBandModel::Params step = damped.ldlt().solve(-jtr);
    if (!step.allFinite()) return false;
    const double trial_cost = model.Linearise(band, use, *q + step, &trial_jtj, &trial_jtr);
    if (std::isfinite(trial_cost) && trial_cost < cost) {
      *q += step;
      // The edge's offset to a ten-thousandth of a pixel is plenty for
      // corners good to hundredths.
      const bool converged =
          cost - trial_cost < 1e-7 * cost || step.head<3>().cwiseAbs().maxCoeff() < 1e-4;
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
  return q->allFinite();
}

// The side's edge fitted to the pixels of a band along it (EdgeBandModel),
// the pixel's area integrated in closed form (erf_pixel_average.h) and the
// blur fitted: no level is read off a profile's ends, which a blur that
// reaches the next module would shift. A second fit leaves out the pixels
// beyond 4 robust sigmas of the first (a bit's corner or a specular spot
// reaching into the band). Returns d's coefficients in t (pixels).
std::optional<Eigen::Vector3d> FitEdgeToPixels(const cv::Mat& gray, const Eigen::Vector2d& a,
                                               const Eigen::Vector2d& u, const Eigen::Vector2d& n,
                                               double length, double half_width, double end_margin,
                                               bool quadratic, double min_contrast) {
  const std::vector<BandPixel> band = CollectBand(gray, a, u, n, length, half_width, end_margin);
  if (band.size() < 20) return std::nullopt;
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
  const EdgeBandModel model{n, quadratic};
  EdgeBandModel::Params q;
  q << 0, 0, 0, 0.5 * (dark + light), 0, 0.5 * (light - dark), 0, std::log(0.8);
  std::vector<char> use(band.size(), 1);
  if (!MinimiseBand(model, band, use, &q)) return std::nullopt;
  std::vector<double> residuals(band.size());
  for (size_t i = 0; i < band.size(); ++i) {
    double u0 = 0;
    ErfPixelAverage m;
    residuals[i] = std::abs(model.Residual(band[i], q, &u0, &m));
  }
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(1.0, 4 * 1.4826 * sorted[sorted.size() / 2]);
  int num_left_out = 0;
  for (size_t i = 0; i < band.size(); ++i) {
    use[i] = residuals[i] <= limit;
    num_left_out += !use[i];
  }
  if (num_left_out > 0 && !MinimiseBand(model, band, use, &q)) return std::nullopt;
  if (q[5] * 2 < min_contrast) return std::nullopt;
  return Eigen::Vector3d(q[0], q[1] / length, q[2] / (length * length));
}

// Each side's curve fitted in a band about the line through the corners
// `c`; false where a side cannot be fitted.
bool FitSides(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
              const std::array<Eigen::Vector2d, 4>& c, std::array<EdgeCurve, 4>* curves,
              std::array<double, 4>* lengths) {
  for (int i = 0; i < 4; ++i) {
    const QuadSide side = SideOfQuad(c, i);
    const Eigen::Vector2d a = side.a, u = side.u, n = side.n;
    const double length = side.length;
    if (length < 8) return false;
    // Stay within the black border module inside and the light module
    // outside: a module's width across this side, which foreshortening
    // makes smaller than along it (the marker's depth from this side, over
    // its modules).
    const double depth = std::min(-(c[(i + 2) % 4] - a).dot(n), -(c[(i + 3) % 4] - a).dot(n));
    const double module = depth / (options.bits_per_side + 2);
    if (module < options.min_module_px) return false;
    const double half_width = std::clamp(0.45 * module, 1.5, 6.0);
    // A bend needs a long side to be measured; short sides are lines.
    const auto fit = FitEdgeToPixels(gray, a, u, n, length, half_width, options.end_margin,
                                     length >= 40, options.min_contrast);
    if (!fit) return false;
    (*curves)[i] = EdgeCurve{a, u, n, *fit};
    (*lengths)[i] = length;
  }
  return true;
}

}  // namespace

bool RefineMarkerCorners(const cv::Mat& gray, const MarkerEdgeRefinementOptions& options,
                         std::array<cv::Point2d, 4>* corners) {
  std::array<Eigen::Vector2d, 4> start, c;
  for (int i = 0; i < 4; ++i) start[i] = c[i] = Eigen::Vector2d((*corners)[i].x, (*corners)[i].y);
  std::array<EdgeCurve, 4> curves;
  std::array<double, 4> lengths;
  // OpenCV's corners of a small, oblique marker can be pixels off, and a
  // band laid about such a line holds the edge off-centre (or a bit's edge
  // too): the bands are laid again about the fitted corners until these
  // stay put.
  for (int pass = 0; pass < options.max_passes; ++pass) {
    if (!FitSides(gray, options, c, &curves, &lengths)) return false;
    std::array<Eigen::Vector2d, 4> next;
    double largest_move = 0;
    for (int i = 0; i < 4; ++i) {
      // Corner i joins side i-1 (c[i-1] -> c[i]) and side i (c[i] -> c[i+1]).
      const int before = (i + 3) % 4;
      const auto x = IntersectCurves(curves[before], lengths[before], curves[i]);
      if (!x) return false;
      next[i] = *x;
      largest_move = std::max(largest_move, (next[i] - c[i]).norm());
    }
    c = next;
    if (largest_move < 0.01) break;
  }
  const double max_shift = std::max(options.max_corner_shift_px,
                                    0.025 * (lengths[0] + lengths[1] + lengths[2] + lengths[3]));
  for (int i = 0; i < 4; ++i) {
    if ((c[i] - start[i]).norm() > max_shift) return false;
  }
  for (int i = 0; i < 4; ++i) (*corners)[i] = cv::Point2d(c[i].x(), c[i].y());
  return true;
}

}  // namespace portcal
