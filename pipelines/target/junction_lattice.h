// The junctions of a chessboard seen in an image, on their lattice: OpenCV's
// SB detector (findChessboardCornersSB with CALIB_CB_LARGER) gives a
// rectangular grid, whose regular parts seed the lattice; it is grown
// junction by junction to every neighbour that is an X-junction of
// the expected colours (a board cut diagonally by the image's border, a
// line SB missed or skipped). Lattice index (i, j): i down the seed's
// rows, j along them.
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

namespace portcal {

// SB's grid: h rows of w junctions, row-major, OpenCV pixels.
struct SeenGrid {
  int h = 0, w = 0;
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector2d& At(int i, int j) const { return points[i * w + j]; }
};

// The largest grid of junctions (3 x 3 or more) SB finds; nullopt for none.
std::optional<SeenGrid> SeeChessboardGrid(const cv::Mat& image);

// The grid's junctions as OpenCV orders a whole cols x rows board's
// (findChessboardCorners), when the grid is the whole board.
std::optional<std::vector<cv::Point2f>> WholeBoard(const SeenGrid& grid, int cols, int rows);

class JunctionLattice {
 public:
  // SB's grid grown in `image` from its regular parts (the largest
  // lattice); nullopt where no part is regular with dark and light squares
  // in turn (not a chessboard's).
  static std::optional<JunctionLattice> Grow(const cv::Mat& image, const SeenGrid& grid);

  const std::map<std::pair<int, int>, Eigen::Vector2d>& points() const { return points_; }
  bool Seen(int i, int j) const { return points_.count({i, j}) > 0; }
  // Where lattice point (i, j) (fractional: a square's centre) lies by the
  // seen junctions' homography.
  Eigen::Vector2d Predict(double i, double j) const;
  // Whether the square whose top-left junction is (i, j) is dark, by the
  // seed's colours.
  bool DarkSquare(int i, int j) const { return ((((i + j) % 2) + 2) % 2 == 0) == dark_at_origin_; }
  // Whether (i, j) would lie beyond the image or within half a square of
  // its border, where a junction cannot be seen.
  bool Hidden(int i, int j, const cv::Size& size) const;
  // Mean gray of a square's centre; nullopt beyond the image.
  std::optional<double> SquareGray(const cv::Mat& image, int i, int j) const;
  double Threshold() const { return 0.5 * (dark_ + light_); }

 private:
  // A lattice of the seed alone, its squares' colours read; nullopt where
  // they do not alternate.
  static std::optional<JunctionLattice> Seeded(const cv::Mat& image, const SeenGrid& seed);
  void Expand(const cv::Mat& image);
  void FitHomography();
  bool IsJunction(const cv::Mat& image, int i, int j, Eigen::Vector2d* p) const;

  std::map<std::pair<int, int>, Eigen::Vector2d> points_;
  Eigen::Matrix3d homography_ = Eigen::Matrix3d::Identity();  // (j, i, 1) -> image
  double dark_ = 0, light_ = 0;
  bool dark_at_origin_ = true;
};

}  // namespace portcal
