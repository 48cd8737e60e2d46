// What is printed on a planar face: gray level as a function of the face
// coordinates (x, y), metres. Edges are exact (no texture resampling), so a
// supersampled render is an exact box-filtered image of the print.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

namespace portcal {

// Gray levels of a print (0-255 scale).
struct PrintLevels {
  double white = 220;
  double black = 30;
  double background = 110;  // where no ray hits anything
  double invalid = 0;       // rays lost to total internal reflection
  double back = 90;         // the back side of a face
};

class FaceTexture {
 public:
  virtual ~FaceTexture() = default;
  // Gray level at (x, y) in the face frame; false outside the face.
  virtual bool Gray(double x, double y, float* gray) const = 0;
  // [min x, max x, min y, max y] of the face.
  virtual Eigen::Vector4d Extent() const = 0;
};

// Inner corners at (c * square, r * square); the square touching corner 0
// diagonally ([-square, 0]^2) is black; a white margin around the squares.
class ChessboardTexture : public FaceTexture {
 public:
  ChessboardTexture(int inner_cols, int inner_rows, double square, double margin,
                    const PrintLevels& levels);
  bool Gray(double x, double y, float* gray) const override;
  Eigen::Vector4d Extent() const override;

 private:
  int cols_, rows_;
  double square_, margin_;
  float white_, black_;
};

// An ArUco marker placed on a face: its corners (top-left, top-right,
// bottom-right, bottom-left of the print) and its modules.
struct PlacedMarker {
  int id = 0;
  std::array<Eigen::Vector2d, 4> corners;
  int modules_per_side = 0;      // including the black border
  std::vector<uint8_t> modules;  // row-major, 1 = white
};

// White print with ArUco markers and, optionally, chessboard squares
// (ChArUco: black squares where no marker is). Markers are looked up through
// a uniform grid.
class MarkerBoardTexture : public FaceTexture {
 public:
  MarkerBoardTexture(std::vector<PlacedMarker> markers, const Eigen::Vector4d& extent,
                     const PrintLevels& levels);
  // ChArUco: squares of `square` from (0, 0) to (squares_x, squares_y);
  // `white_squares` lists the (i, j) that hold markers.
  void SetSquares(int squares_x, int squares_y, double square);
  bool Gray(double x, double y, float* gray) const override;
  Eigen::Vector4d Extent() const override { return extent_; }

 private:
  bool MarkerGray(const PlacedMarker& marker, double x, double y, float* gray) const;

  std::vector<PlacedMarker> markers_;
  Eigen::Vector4d extent_;
  float white_, black_;
  int squares_x_ = 0, squares_y_ = 0;
  double square_ = 0;
  std::vector<uint8_t> square_has_marker_;
  // Uniform grid over the extent -> candidate markers.
  double cell_ = 1;
  int grid_cols_ = 1, grid_rows_ = 1;
  std::vector<std::vector<int>> grid_;
};

struct Dot {
  double x = 0, y = 0, radius = 0;
  float gray = 0;
};

// A face of the masking auto-calibration target: random dots on white, one
// ArUco marker (with a white quiet zone) at the centre.
class DotsFaceTexture : public FaceTexture {
 public:
  DotsFaceTexture(std::vector<Dot> dots, PlacedMarker marker, double quiet_zone,
                  const Eigen::Vector4d& extent, const PrintLevels& levels);
  bool Gray(double x, double y, float* gray) const override;
  Eigen::Vector4d Extent() const override { return extent_; }

 private:
  std::vector<Dot> dots_;
  MarkerBoardTexture marker_;
  Eigen::Vector4d marker_zone_;
  Eigen::Vector4d extent_;
  float white_;
  double cell_ = 1;
  int grid_cols_ = 1, grid_rows_ = 1;
  std::vector<std::vector<int>> grid_;
};

// A raster (8-bit) covering [x0, x0 + cols * texel] x [y0, y0 + rows * texel],
// bilinearly interpolated: clutter and seabed textures.
class RasterTexture : public FaceTexture {
 public:
  RasterTexture(cv::Mat image, double x0, double y0, double texel);
  bool Gray(double x, double y, float* gray) const override;
  Eigen::Vector4d Extent() const override;

 private:
  cv::Mat image_;
  double x0_, y0_, texel_;
};

// Random shapes (discs, rectangles, stripes) of random gray: textured
// clutter and seabeds that give many SIFT features.
cv::Mat RandomShapesRaster(int cols, int rows, int num_shapes, uint64_t seed, int min_size_px,
                           int max_size_px);

}  // namespace portcal
