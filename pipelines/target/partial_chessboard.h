// A plain chessboard seen only in part, cut by the image's border: which of
// the board's corners the seen junctions (junction_lattice.h) are follows
// from where they end. Every placement of the lattice on the board is tried
// (the four turns that keep portcal's right-handed order, at every offset)
// and kept only if
//  - every seen junction lands on the board;
//  - every board corner it puts in the image (more than half a square
//    inside) was seen: where the junctions end inside the image, the
//    board's edge must be;
//  - the squares' colours match the board's, over the seen squares and the
//    ring around them wherever it is in the image (beyond a board edge the
//    outer squares, which an occluder would not mimic).
// The view is used when one placement is left, or two that are the board
// turned by 180 degrees on a board that looks the same so; otherwise it is
// refused with the reason (e.g. a board cut on both sides of one axis, or
// ending inside the image where an occluder hides it).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipelines/target/junction_lattice.h"

namespace portcal {

struct PartialChessboard {
  // Canonical order (index r * cols + c, corner 0's outer diagonal square
  // black), OpenCV pixels of the searched image; every corner is given,
  // those not seen placed by the seen ones' homography.
  std::vector<Eigen::Vector2d> corners;
  std::vector<bool> seen;
  bool symmetric = false;  // the order may be the board turned by 180 degrees
};

// What placing the junctions on the board gave: the board, or the reason
// there is none (more junctions than the board has, no place on the board
// that fits, several).
struct PartialPlacement {
  std::optional<PartialChessboard> board;
  std::string reason;
};

PartialPlacement PlaceOnChessboard(const cv::Mat& image, const JunctionLattice& lattice, int cols,
                                   int rows);

}  // namespace portcal
