#include "pipelines/target/partial_chessboard.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>

namespace portcal {
namespace {

// A place of the lattice on the board: lattice (i, j) is board corner
// (r, c) = (r0 + a i + b j, c0 + e i + f j), M = [a b; e f] a signed
// permutation (so lattice (i, j) = M^T (r - r0, c - c0)).
struct Placement {
  int a, b, e, f, r0, c0;
  Eigen::Vector2i Map(int i, int j) const { return {r0 + a * i + b * j, c0 + e * i + f * j}; }
  Eigen::Vector2i Unmap(int r, int c) const {
    return {a * (r - r0) + e * (c - c0), b * (r - r0) + f * (c - c0)};
  }
};

struct Board {
  int cols, rows;
  bool Has(const Eigen::Vector2i& q) const {
    return q.x() >= 0 && q.y() >= 0 && q.x() < rows && q.y() < cols;
  }
};

struct LatticeBounds {
  int i0 = 1 << 20, i1 = -(1 << 20), j0 = 1 << 20, j1 = -(1 << 20);
};

LatticeBounds BoundsOf(const JunctionLattice& lattice) {
  LatticeBounds bounds;
  for (const auto& [ij, p] : lattice.points()) {
    bounds.i0 = std::min(bounds.i0, ij.first);
    bounds.i1 = std::max(bounds.i1, ij.first);
    bounds.j0 = std::min(bounds.j0, ij.second);
    bounds.j1 = std::max(bounds.j1, ij.second);
  }
  return bounds;
}

// The squares of the seen lattice and the ring around it, by their
// top-left junction, with their gray where it is in the image.
struct Square {
  int i, j;
  double gray;
};

std::vector<Square> SampleSquares(const cv::Mat& image, const JunctionLattice& lattice,
                                  const LatticeBounds& b) {
  std::vector<Square> squares;
  for (int i = b.i0 - 1; i <= b.i1; ++i) {
    for (int j = b.j0 - 1; j <= b.j1; ++j) {
      // Only squares touching a seen junction: the ring around what is seen.
      bool near = false;
      for (const auto& [di, dj] : {std::pair{0, 0}, {0, 1}, {1, 0}, {1, 1}})
        near = near || lattice.Seen(i + di, j + dj);
      if (!near) continue;
      const auto gray = lattice.SquareGray(image, i, j);
      if (gray) squares.push_back({i, j, *gray});
    }
  }
  return squares;
}

bool ColoursMatch(const Placement& place, const std::vector<Square>& squares, double threshold,
                  const Board& board) {
  int checked = 0, wrong = 0;
  for (const Square& square : squares) {
    const Eigen::Vector2i q00 = place.Map(square.i, square.j),
                          q11 = place.Map(square.i + 1, square.j + 1);
    // Square (sr, sc) lies between corner rows sr - 1 and sr, columns
    // sc - 1 and sc; square (0, 0), corner 0's outer diagonal one, is black.
    const int sr = std::max(q00.x(), q11.x()), sc = std::max(q00.y(), q11.y());
    if (sr < 0 || sc < 0 || sr > board.rows || sc > board.cols) continue;  // the margin
    ++checked;
    wrong += ((sr + sc) % 2 == 0) != (square.gray < threshold);
  }
  return checked > 0 && wrong <= checked / 10;
}

// Every seen junction on the board, and every board corner in view seen.
bool SeenWhereInView(const Placement& place, const JunctionLattice& lattice, const Board& board,
                     const cv::Size& size) {
  for (const auto& [ij, p] : lattice.points()) {
    if (!board.Has(place.Map(ij.first, ij.second))) return false;
  }
  for (int r = 0; r < board.rows; ++r) {
    for (int c = 0; c < board.cols; ++c) {
      const Eigen::Vector2i ij = place.Unmap(r, c);
      if (!lattice.Seen(ij.x(), ij.y()) && !lattice.Hidden(ij.x(), ij.y(), size)) return false;
    }
  }
  return true;
}

std::vector<Placement> FittingPlacements(const cv::Mat& image, const JunctionLattice& lattice,
                                         const LatticeBounds& bounds, const Board& board) {
  const std::vector<Square> squares = SampleSquares(image, lattice, bounds);
  const Eigen::Vector2d origin = lattice.Predict(bounds.i0, bounds.j0);
  const Eigen::Vector2d vi = lattice.Predict(bounds.i0 + 1, bounds.j0) - origin;
  const Eigen::Vector2d vj = lattice.Predict(bounds.i0, bounds.j0 + 1) - origin;
  const std::array<std::array<int, 4>, 8> turns = {{{1, 0, 0, 1},
                                                    {-1, 0, 0, -1},
                                                    {1, 0, 0, -1},
                                                    {-1, 0, 0, 1},
                                                    {0, 1, 1, 0},
                                                    {0, -1, -1, 0},
                                                    {0, 1, -1, 0},
                                                    {0, -1, 1, 0}}};
  const int reach =
      std::abs(bounds.i0) + std::abs(bounds.i1) + std::abs(bounds.j0) + std::abs(bounds.j1) + 1;
  std::vector<Placement> fitting;
  for (const auto& [a, b, e, f] : turns) {
    // Along a row (+c) and down a column (+r) in the image: right-handed.
    const Eigen::Vector2d along_row = e * vi + f * vj, along_column = a * vi + b * vj;
    if (along_row.x() * along_column.y() - along_row.y() * along_column.x() <= 0) continue;
    for (int r0 = -reach; r0 <= board.rows + reach; ++r0) {
      for (int c0 = -reach; c0 <= board.cols + reach; ++c0) {
        const Placement place{a, b, e, f, r0, c0};
        if (!board.Has(place.Map(bounds.i0, bounds.j0)) ||
            !board.Has(place.Map(bounds.i1, bounds.j1)))
          continue;
        if (ColoursMatch(place, squares, lattice.Threshold(), board) &&
            SeenWhereInView(place, lattice, board, image.size())) {
          fitting.push_back(place);
        }
      }
    }
  }
  return fitting;
}

// The board turned by 180 degrees takes corner (r, c) to
// (rows - 1 - r, cols - 1 - c).
bool TurnedByHalf(const Placement& p, const Placement& q, const JunctionLattice& lattice,
                  const Board& board) {
  for (const auto& [ij, point] : lattice.points()) {
    if (q.Map(ij.first, ij.second) !=
        Eigen::Vector2i(board.rows - 1, board.cols - 1) - p.Map(ij.first, ij.second)) {
      return false;
    }
  }
  return true;
}

PartialChessboard PlaceOnBoard(const Placement& place, const JunctionLattice& lattice,
                               const Board& board) {
  PartialChessboard result;
  result.corners.resize(board.cols * board.rows);
  result.seen.assign(board.cols * board.rows, false);
  for (int r = 0; r < board.rows; ++r) {
    for (int c = 0; c < board.cols; ++c) {
      const Eigen::Vector2i ij = place.Unmap(r, c);
      const auto it = lattice.points().find({ij.x(), ij.y()});
      result.seen[r * board.cols + c] = it != lattice.points().end();
      result.corners[r * board.cols + c] =
          result.seen[r * board.cols + c] ? it->second : lattice.Predict(ij.x(), ij.y());
    }
  }
  return result;
}

}  // namespace

PartialPlacement PlaceOnChessboard(const cv::Mat& image, const JunctionLattice& lattice, int cols,
                                   int rows) {
  PartialPlacement placement;
  const Board board{cols, rows};
  const LatticeBounds bounds = BoundsOf(lattice);
  const int num_rows = bounds.i1 - bounds.i0 + 1, num_cols = bounds.j1 - bounds.j0 + 1;
  const bool too_large =
      !((num_rows <= rows && num_cols <= cols) || (num_rows <= cols && num_cols <= rows));
  const std::string seen = std::to_string(lattice.points().size()) + " junctions over " +
                           std::to_string(num_cols) + "x" + std::to_string(num_rows) + " seen";
  const std::string looked_for = std::to_string(cols) + "x" + std::to_string(rows) + " board";
  if (too_large) {
    placement.reason = seen + ": more than the " + looked_for + " has (another board)";
    return placement;
  }
  const std::vector<Placement> fitting = FittingPlacements(image, lattice, bounds, board);
  if (fitting.empty()) {
    placement.reason =
        seen + ", but they fit nowhere on the " + looked_for +
        " with its cut sides at the image's border (another board, or one partly hidden)";
    return placement;
  }
  const bool symmetric =
      fitting.size() == 2 && TurnedByHalf(fitting[0], fitting[1], lattice, board);
  if (fitting.size() > 1 && !symmetric) {
    placement.reason = seen + ", which " + std::to_string(fitting.size()) + " places on the " +
                       looked_for +
                       " fit (its part cannot be told: more of the board must be seen)";
    return placement;
  }
  placement.board = PlaceOnBoard(fitting[0], lattice, board);
  placement.board->symmetric = symmetric;
  return placement;
}

}  // namespace portcal
