#include "pipelines/target/junction_lattice.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace portcal {
namespace {

// Mean gray of a small box about `centre`; nullopt where it leaves the image.
std::optional<double> BoxGray(const cv::Mat& image, const Eigen::Vector2d& centre, double half) {
  const int r = std::max(1, static_cast<int>(half));
  const int x = static_cast<int>(std::lround(centre.x())),
            y = static_cast<int>(std::lround(centre.y()));
  if (x - r < 0 || y - r < 0 || x + r >= image.cols || y + r >= image.rows) return std::nullopt;
  return cv::mean(image(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1)))[0];
}

}  // namespace

std::optional<SeenGrid> SeeChessboardGrid(const cv::Mat& image) {
  std::vector<cv::Point2f> points;
  cv::Mat meta;
  const int flags = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_LARGER;
  if (!cv::findChessboardCornersSB(image, cv::Size(3, 3), points, flags, meta) || meta.empty())
    return std::nullopt;
  SeenGrid grid;
  grid.h = meta.rows;
  grid.w = meta.cols;
  for (const cv::Point2f& p : points) grid.points.emplace_back(p.x, p.y);
  if (static_cast<int>(grid.points.size()) != grid.h * grid.w || grid.h < 3 || grid.w < 3)
    return std::nullopt;
  return grid;
}

std::optional<std::vector<cv::Point2f>> WholeBoard(const SeenGrid& grid, int cols, int rows) {
  const bool as_is = grid.h == rows && grid.w == cols,
             transposed = grid.h == cols && grid.w == rows;
  if (!as_is && !transposed) return std::nullopt;
  std::vector<cv::Point2f> corners(cols * rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d& p = as_is ? grid.At(r, c) : grid.At(c, r);
      corners[r * cols + c] = cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
  }
  return corners;
}

void JunctionLattice::FitHomography() {
  std::vector<cv::Point2f> lattice, image;
  for (const auto& [ij, p] : points_) {
    lattice.emplace_back(static_cast<float>(ij.second), static_cast<float>(ij.first));
    image.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  const cv::Mat h = cv::findHomography(lattice, image);
  if (h.empty()) return;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) homography_(r, c) = h.at<double>(r, c);
  }
}

Eigen::Vector2d JunctionLattice::Predict(double i, double j) const {
  const Eigen::Vector3d q = homography_ * Eigen::Vector3d(j, i, 1);
  return q.head<2>() / q.z();
}

bool JunctionLattice::Hidden(int i, int j, const cv::Size& size) const {
  const Eigen::Vector2d p = Predict(i, j);
  const double margin =
      0.5 * std::min((Predict(i, j + 1) - p).norm(), (Predict(i + 1, j) - p).norm());
  return p.x() < margin || p.y() < margin || p.x() > size.width - margin ||
         p.y() > size.height - margin;
}

std::optional<double> JunctionLattice::SquareGray(const cv::Mat& image, int i, int j) const {
  const double side = std::min((Predict(i, j + 1) - Predict(i, j)).norm(),
                               (Predict(i + 1, j) - Predict(i, j)).norm());
  return BoxGray(image, Predict(i + 0.5, j + 0.5), 0.15 * side);
}

// An X-junction of the expected colours at (i, j): its four squares'
// grays (a quarter of a square off along the diagonals) on the expected
// sides of the threshold and as far apart as half the board's contrast;
// then its position by cornerSubPix, which must stay within a quarter of
// a square of the prediction.
bool JunctionLattice::IsJunction(const cv::Mat& image, int i, int j, Eigen::Vector2d* p) const {
  const Eigen::Vector2d predicted = Predict(i, j);
  const Eigen::Vector2d u = 0.5 * (Predict(i, j + 1) - Predict(i, j - 1)),
                        v = 0.5 * (Predict(i + 1, j) - Predict(i - 1, j));
  const double side = std::min(u.norm(), v.norm());
  double dark_sum = 0, light_sum = 0;
  for (const auto& [di, dj] : {std::pair{0, 0}, {-1, -1}, {-1, 0}, {0, -1}}) {
    const Eigen::Vector2d at = predicted + (dj + 0.5) * 0.5 * u + (di + 0.5) * 0.5 * v;
    const auto gray = BoxGray(image, at, 0.1 * side);
    if (!gray) return false;
    const bool dark = DarkSquare(i + di, j + dj);
    if ((*gray < Threshold()) != dark) return false;
    (dark ? dark_sum : light_sum) += 0.5 * *gray;
  }
  if (light_sum - dark_sum < 0.5 * (light_ - dark_)) return false;
  std::vector<cv::Point2f> corner = {
      cv::Point2f(static_cast<float>(predicted.x()), static_cast<float>(predicted.y()))};
  const int half = std::max(2, static_cast<int>(0.2 * side));
  cv::cornerSubPix(image, corner, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.01));
  *p = Eigen::Vector2d(corner[0].x, corner[0].y);
  return (*p - predicted).norm() < 0.25 * side;
}

namespace {

// The regular parts of SB's grid (3 x 3 junctions, then 3 x 2 and 2 x 3),
// each as a grid of its own, the most regular first: SB's larger grids can
// skip a line of junctions (seen on views cut by the image's border), and
// a grid that skips one is no lattice. A part is regular where the
// homography of its junctions is nowhere off by a tenth of a square.
std::vector<SeenGrid> RegularParts(const SeenGrid& grid) {
  std::vector<std::pair<double, SeenGrid>> parts;
  for (const auto& [h, w] : {std::pair{3, 3}, {3, 2}, {2, 3}}) {
    for (int i0 = 0; i0 + h <= grid.h; ++i0) {
      for (int j0 = 0; j0 + w <= grid.w; ++j0) {
        SeenGrid part{h, w, {}};
        std::vector<cv::Point2f> lattice, image;
        for (int i = 0; i < h; ++i) {
          for (int j = 0; j < w; ++j) {
            part.points.push_back(grid.At(i0 + i, j0 + j));
            lattice.emplace_back(static_cast<float>(j), static_cast<float>(i));
            image.emplace_back(static_cast<float>(part.points.back().x()),
                               static_cast<float>(part.points.back().y()));
          }
        }
        const cv::Mat homography = cv::findHomography(lattice, image);
        if (homography.empty()) continue;
        std::vector<cv::Point2f> predicted;
        cv::perspectiveTransform(lattice, predicted, homography);
        const double step = std::min(cv::norm(image[1] - image[0]), cv::norm(image[w] - image[0]));
        double worst = 0;
        for (size_t k = 0; k < image.size(); ++k)
          worst = std::max(worst, cv::norm(predicted[k] - image[k]) / step);
        // 3 x 3 parts before the smaller ones, each kind by regularity.
        if (worst < 0.1) parts.emplace_back(worst + (h * w == 9 ? 0 : 1), std::move(part));
      }
    }
  }
  std::stable_sort(parts.begin(), parts.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<SeenGrid> regular;
  for (auto& [score, part] : parts) regular.push_back(std::move(part));
  return regular;
}

}  // namespace

std::optional<JunctionLattice> JunctionLattice::Seeded(const cv::Mat& image, const SeenGrid& seed) {
  JunctionLattice lattice;
  for (int i = 0; i < seed.h; ++i) {
    for (int j = 0; j < seed.w; ++j) lattice.points_[{i, j}] = seed.At(i, j);
  }
  lattice.FitHomography();
  // The seed's squares: which parity is dark, and the two levels; every
  // square on its parity's side of the levels' midpoint.
  std::vector<std::pair<int, double>> squares;  // parity, gray
  double sums[2] = {0, 0};
  int counts[2] = {0, 0};
  for (int i = 0; i + 1 < seed.h; ++i) {
    for (int j = 0; j + 1 < seed.w; ++j) {
      const auto gray = lattice.SquareGray(image, i, j);
      if (!gray) continue;
      squares.emplace_back((i + j) % 2, *gray);
      sums[(i + j) % 2] += *gray;
      ++counts[(i + j) % 2];
    }
  }
  if (counts[0] == 0 || counts[1] == 0) return std::nullopt;
  const double even = sums[0] / counts[0], odd = sums[1] / counts[1];
  lattice.dark_at_origin_ = even < odd;
  lattice.dark_ = std::min(even, odd);
  lattice.light_ = std::max(even, odd);
  if (lattice.light_ - lattice.dark_ < 10) return std::nullopt;
  for (const auto& [parity, gray] : squares) {
    if ((gray < lattice.Threshold()) != ((parity == 0) == lattice.dark_at_origin_))
      return std::nullopt;
  }
  return lattice;
}

void JunctionLattice::Expand(const cv::Mat& image) {
  // Breadth first from every seen junction to its four neighbours; the
  // homography is refitted as the lattice grows, so that predictions far
  // from the seed follow the lens.
  std::deque<std::pair<int, int>> queue;
  for (const auto& [ij, p] : points_) queue.push_back(ij);
  int since_fit = 0;
  while (!queue.empty()) {
    const auto [i, j] = queue.front();
    queue.pop_front();
    for (const auto& [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const int ni = i + di, nj = j + dj;
      Eigen::Vector2d p;
      if (Seen(ni, nj) || Hidden(ni, nj, image.size()) || !IsJunction(image, ni, nj, &p)) continue;
      points_[{ni, nj}] = p;
      queue.emplace_back(ni, nj);
      if (++since_fit >= 4) {
        FitHomography();
        since_fit = 0;
      }
    }
  }
  FitHomography();
}

std::optional<JunctionLattice> JunctionLattice::Grow(const cv::Mat& image, const SeenGrid& grid) {
  // Up to the 6 most regular parts, each grown; the largest lattice wins
  // (SB's grid for one image differed from run to run, in parts).
  std::optional<JunctionLattice> best;
  const std::vector<SeenGrid> parts = RegularParts(grid);
  for (size_t k = 0; k < parts.size() && k < 6; ++k) {
    std::optional<JunctionLattice> lattice = Seeded(image, parts[k]);
    if (!lattice) continue;
    lattice->Expand(image);
    if (!best || lattice->points_.size() > best->points_.size()) best = std::move(lattice);
  }
  return best;
}

}  // namespace portcal
