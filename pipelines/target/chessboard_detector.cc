#include "pipelines/target/chessboard_detector.h"

#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "colmap_ext/util/error.h"
#include "pipelines/target/coarse_level.h"
#include "pipelines/target/junction_lattice.h"
#include "pipelines/target/partial_chessboard.h"

namespace portcal {

void ChessboardDetectionOptions::Check() const {
  if (cols < 2) throw OptionError("--Target.cols", cols, ">= 2 inner corners");
  if (rows < 2) throw OptionError("--Target.rows", rows, ">= 2 inner corners");
  if (coarse_max_image_size < 0) {
    throw OptionError("--Target.coarse_max_image_size", coarse_max_image_size, ">= 0");
  }
  if (!(min_x_corner_fraction >= 0 && min_x_corner_fraction <= 1)) {
    throw OptionError("--Target.min_x_corner_fraction", min_x_corner_fraction, "[0, 1]");
  }
  if (min_refined_corners < 4) {
    throw OptionError("--Target.min_refined_corners", min_refined_corners, ">= 4");
  }
  refinement.Check();
}

namespace {

// Where a search for the board starts: the coarse level (and the image
// itself when that is smaller) and whether the X-junction count lets the
// image be searched at all (else the reason).
struct SearchLevels {
  std::vector<std::pair<double, cv::Mat>> levels;  // (scale, image), coarse first
  bool searched = false;
};

SearchLevels GateAndLevels(const cv::Mat& gray, const ChessboardDetectionOptions& options,
                           std::string* reason) {
  SearchLevels search;
  search.levels = {CoarseLevel(gray, options.coarse_max_image_size)};
  if (search.levels.front().first < 1) search.levels.emplace_back(1.0, gray);
  const int num_crossings = std::max(options.cols - 2, 1) * std::max(options.rows - 2, 1);
  const int needed = static_cast<int>(std::ceil(options.min_x_corner_fraction * num_crossings));
  if (needed > 0) {
    const int count = CountXCorners(search.levels.front().second, {}, needed);
    if (count < needed) {
      *reason = "no " + std::to_string(options.cols) + "x" + std::to_string(options.rows) +
                " inner-corner chessboard in view (" + std::to_string(count) +
                " chessboard-like grid junctions, fewer than " + std::to_string(needed) + ")";
      return search;
    }
  }
  search.searched = true;
  return search;
}

// The whole board by OpenCV's classic detector on the coarse level with a
// global threshold: a few ms where the adaptive one took up to 0.2 s on a
// render (docs/benchmarks_target_detection.md).
bool FindWholeQuickly(const SearchLevels& search, const ChessboardDetectionOptions& options,
                      std::vector<cv::Point2f>* corners, double* scale) {
  *scale = search.levels.front().first;
  return cv::findChessboardCorners(search.levels.front().second,
                                   cv::Size(options.cols, options.rows), *corners,
                                   cv::CALIB_CB_NORMALIZE_IMAGE);
}

// The whole board by the slower searches: the classic detector's adaptive
// threshold on the coarse level without its fast check (which misses
// small boards there and which the X-junction count replaces), at full
// resolution with it; the classic detector finds boards on the real views
// that the SB detector misses. Then the SB detector (exhaustive) at each
// scale.
bool FindWholeSlowly(const SearchLevels& search, const ChessboardDetectionOptions& options,
                     std::vector<cv::Point2f>* corners, double* scale) {
  const cv::Size pattern(options.cols, options.rows);
  const int adaptive = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
  const bool gated = options.min_x_corner_fraction > 0;
  std::vector<std::pair<size_t, int>> attempts = {
      {0, adaptive | (gated ? 0 : cv::CALIB_CB_FAST_CHECK)}};
  if (search.levels.size() > 1) attempts.emplace_back(1, adaptive | cv::CALIB_CB_FAST_CHECK);
  for (const auto& [level, flags] : attempts) {
    if (cv::findChessboardCorners(search.levels[level].second, pattern, *corners, flags)) {
      *scale = search.levels[level].first;
      return true;
    }
  }
  for (const auto& [factor, image] : search.levels) {
    if (cv::findChessboardCornersSB(image, pattern, *corners,
                                    cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
      *scale = factor;
      return true;
    }
  }
  return false;
}

// Mean gray of the first square inside the grid at corner 0 (between
// corners 0, 1, cols and cols + 1). It has the colour of the square
// diagonally outside corner 0 and, unlike that one, always lies on the
// board (the outer ring may be cut, or printed differently).
double FirstSquareGray(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols) {
  const Eigen::Vector2d centre =
      0.25 * (corners[0] + corners[1] + corners[cols] + corners[cols + 1]);
  const double radius =
      0.15 * std::min((corners[1] - corners[0]).norm(), (corners[cols] - corners[0]).norm());
  double sum = 0;
  int count = 0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const Eigen::Vector2d p = centre + radius * 0.5 * Eigen::Vector2d(dx, dy);
      sum += gray.at<uint8_t>(std::clamp(static_cast<int>(p.y()), 0, gray.rows - 1),
                              std::clamp(static_cast<int>(p.x()), 0, gray.cols - 1));
      ++count;
    }
  }
  return sum / count;
}

// True when the far end's first square (at corner n - 1) is the darker:
// corner 0's diagonal squares are to be the black ones. The two ends are
// compared with each other, not each with the board's mean gray: on the
// OpenCV stereo sample both ends read lighter than the mean, and the answer
// then followed OpenCV's start (the two cameras labelled one board
// differently).
bool FarEndIsBlack(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols) {
  const std::vector<Eigen::Vector2d> reversed(corners.rbegin(), corners.rend());
  return FirstSquareGray(gray, reversed, cols) < FirstSquareGray(gray, corners, cols);
}

// "3 of 48 corners left out (2 no contrast, 1 window beyond the image)".
std::string LeftOutNote(const std::vector<CornerFailure>& failures) {
  std::map<CornerFailure, int> counts;
  for (const CornerFailure failure : failures) {
    if (failure != CornerFailure::kNone) ++counts[failure];
  }
  int total = 0;
  std::string reasons;
  for (const auto& [failure, count] : counts) {
    reasons +=
        (reasons.empty() ? "" : ", ") + std::to_string(count) + " " + CornerFailureText(failure);
    total += count;
  }
  return std::to_string(total) + " of " + std::to_string(failures.size()) + " corners left out" +
         (reasons.empty() ? "" : " (" + reasons + ")");
}

// The quick corners' window: a quarter of the median spacing of corners
// next to each other in a row (never reaching the next corner), 2 to 10 px.
// A fixed 5 x 5 window on a large, soft-edged board left the corners 2-5 px
// apart from frame to frame of a board held still (docs/live.md).
int QuickWindowHalf(const std::vector<bool>& seen, const std::vector<Eigen::Vector2d>& corners,
                    int cols) {
  std::vector<double> spacings;
  for (size_t i = 0; i + 1 < corners.size(); ++i) {
    if (static_cast<int>(i + 1) % cols != 0 && seen[i] && seen[i + 1])
      spacings.push_back((corners[i + 1] - corners[i]).norm());
  }
  if (spacings.empty()) return 2;
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  return std::clamp(static_cast<int>(spacings[spacings.size() / 2] / 4), 2, 10);
}

// cv::cornerSubPix at full resolution on corners in COLMAP pixels.
void PolishQuickly(const cv::Mat& gray, const std::vector<bool>& seen, int cols,
                   std::vector<Eigen::Vector2d>* corners) {
  std::vector<cv::Point2f> points;
  std::vector<size_t> indices;
  for (size_t i = 0; i < corners->size(); ++i) {
    if (!seen[i]) continue;
    points.emplace_back((*corners)[i].x() - 0.5, (*corners)[i].y() - 0.5);
    indices.push_back(i);
  }
  const int half = QuickWindowHalf(seen, *corners, cols);
  cv::cornerSubPix(gray, points, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.01));
  for (size_t k = 0; k < points.size(); ++k)
    (*corners)[indices[k]] = Eigen::Vector2d(points[k].x + 0.5, points[k].y + 0.5);
}

// The whole board's corners (COLMAP pixels of the image) in canonical
// order, from OpenCV's corners on the level scaled by `scale`.
std::vector<Eigen::Vector2d> CanonicalOrder(const cv::Mat& gray,
                                            const std::vector<cv::Point2f>& coarse, double scale,
                                            const ChessboardDetectionOptions& options) {
  // Back to full-resolution COLMAP pixels: OpenCV's (0, 0) is the centre of
  // the top-left pixel, also in the downscaled image.
  std::vector<Eigen::Vector2d> start;
  for (const cv::Point2f& p : coarse) start.emplace_back((p.x + 0.5) / scale, (p.y + 0.5) / scale);
  // Right-handed order: the rows run to the right of the columns as the
  // board is seen from the front (target x cross y away from the camera).
  // findChessboardCorners may return the mirror image, a labelling no board
  // pose can give, which breaks the correspondence between two cameras'
  // views of one board.
  const Eigen::Vector2d along_row = start[1] - start[0],
                        along_column = start[options.cols] - start[0];
  if (along_row.x() * along_column.y() - along_row.y() * along_column.x() < 0) {
    for (int r = 0; r < options.rows; ++r) {
      std::reverse(start.begin() + r * options.cols, start.begin() + (r + 1) * options.cols);
    }
  }
  // Canonical order: corner 0's outer diagonal square is black. OpenCV may
  // start at the far corner (the same grid rotated by 180 degrees).
  if (FarEndIsBlack(gray, start, options.cols)) std::reverse(start.begin(), start.end());
  return start;
}

// The part of the board in view, from SB's grid grown to every junction in
// view (junction_lattice.h) and placed on the board (partial_chessboard.h):
// every corner in full-resolution COLMAP pixels, those out of view marked
// unseen; no board with the reason. nullopt where SB's grid gives no
// lattice.
std::optional<PartialPlacement> PlacePartly(const SearchLevels& search, const SeenGrid& grid,
                                            const ChessboardDetectionOptions& options) {
  const cv::Mat& level = search.levels.front().second;
  const auto lattice = JunctionLattice::Grow(level, grid);
  if (!lattice) return std::nullopt;
  PartialPlacement placement = PlaceOnChessboard(level, *lattice, options.cols, options.rows);
  if (placement.board) {
    for (Eigen::Vector2d& p : placement.board->corners)
      p = (p + Eigen::Vector2d(0.5, 0.5)) / search.levels.front().first;
  }
  return placement;
}

// Where the board's corners start from: the whole board, or the part of
// it in view. The order of the searches: the classic detector's quickest;
// SB's grid of every junction it sees (0.06-0.1 s on 800 x 600), which is
// the whole board or, cut by the image's border, the part in view; only
// then, only where SB's junctions give no lattice, the slower searches for
// the whole board (the classic detector's adaptive threshold spent 6-8 s
// on an 800 x 600 view of a board cut by the image's border, 5 s on one of
// a board of other dimensions, and found nothing; docs/benchmarks_target_detection.md). A
// lattice holds every X-junction in view, so where it does not fit the
// board (more junctions than it has, none of it in view, or only in part
// and not where the image cuts it) the whole board is not in view either.
// False with the reason.
bool FindStart(const cv::Mat& gray, const ChessboardDetectionOptions& options,
               std::vector<Eigen::Vector2d>* start, std::vector<bool>* seen, double* scale,
               ChessboardDetection* detection) {
  const int squares = (options.cols + 1) + (options.rows + 1);
  detection->symmetric = squares % 2 == 0;
  const SearchLevels search = GateAndLevels(gray, options, &detection->reason);
  if (!search.searched) return false;
  std::vector<cv::Point2f> coarse;
  bool whole = FindWholeQuickly(search, options, &coarse, scale);
  std::optional<SeenGrid> grid;
  if (!whole) {
    grid = SeeChessboardGrid(search.levels.front().second);
    const auto corners = grid ? WholeBoard(*grid, options.cols, options.rows) : std::nullopt;
    if (corners) coarse = *corners;
    whole = corners.has_value();
  }
  const std::string board = std::to_string(options.cols) + "x" + std::to_string(options.rows) +
                            " inner-corner chessboard";
  if (!whole && grid) {
    const auto partial = PlacePartly(search, *grid, options);
    if (partial && partial->board && options.partial_views) {
      *start = partial->board->corners;
      *seen = partial->board->seen;
      *scale = search.levels.front().first;
      detection->symmetric = partial->board->symmetric;
      detection->partial = true;
      return true;
    }
    if (partial) {
      detection->reason =
          "no " + board + " found" +
          (partial->board ? " whole (--Target.partial_views 0)" : ": " + partial->reason);
      return false;
    }
  }
  if (!whole) whole = FindWholeSlowly(search, options, &coarse, scale);
  if (!whole) {
    detection->reason = "no " + board + " found";
    return false;
  }
  *start = CanonicalOrder(gray, coarse, *scale, options);
  seen->assign(start->size(), true);
  return true;
}

}  // namespace

ChessboardDetection DetectChessboard(const cv::Mat& gray,
                                     const ChessboardDetectionOptions& options) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  ChessboardDetection detection;
  std::vector<Eigen::Vector2d> start;
  std::vector<bool> seen;
  double scale = 1.0;
  if (!FindStart(gray, options, &start, &seen, &scale, &detection)) return detection;
  detection.reason.clear();
  if (!options.precise_fit) {
    PolishQuickly(gray, seen, options.cols, &start);
    detection.corners.resize(start.size());
    for (size_t i = 0; i < start.size(); ++i) {
      if (seen[i]) detection.corners[i] = start[i];
    }
    detection.num_refined = static_cast<int>(std::count(seen.begin(), seen.end(), true));
    detection.found = true;
    return detection;
  }
  // The coarse corners are as good as their level's pixels: a corner may
  // move by the refinement's maximum in those pixels.
  CornerRefinementOptions refinement = options.refinement;
  refinement.max_shift_px /= scale;
  std::vector<CornerFailure> failures;
  const auto refined = RefineChessboardCorners(gray, start, options.cols, options.rows, refinement,
                                               &failures, &seen);
  detection.corners.resize(refined.size());
  std::set<int> rows, cols;
  for (size_t i = 0; i < refined.size(); ++i) {
    if (!refined[i]) continue;
    detection.corners[i] = refined[i]->xy;
    ++detection.num_refined;
    rows.insert(static_cast<int>(i) / options.cols);
    cols.insert(static_cast<int>(i) % options.cols);
  }
  const std::string left_out = LeftOutNote(failures);
  if (detection.num_refined < options.min_refined_corners || rows.size() < 2 || cols.size() < 2) {
    detection.reason = "board found but too few corners for a pose: " + left_out;
    return detection;
  }
  detection.found = true;
  if (detection.num_refined < static_cast<int>(refined.size())) detection.note = left_out;
  return detection;
}

}  // namespace portcal
