// Chessboards cut by the image's border (issue 24, item 2): on renders
// where only the board's centre is kept in view, the views whose part of
// the board can be told keep their corners in view, each at its own place
// on the board; the others are refused with the reason, never placed
// wrongly.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/target/chessboard_detector.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

TEST(PartialViews, CornersInViewKeptAtTheirPlaceOnTheBoard) {
  testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(
      dir,
      "name: partial\nseed: 41\nnum_images: 16\n"
      "camera: {model: RADIAL, width: 800, height: 600, params: [650.0, 402.0, 298.0, -0.08, "
      "0.01]}\n"
      "housing: null\ntarget: {type: chessboard, cols: 9, rows: 6, square_size: 0.025, margin: "
      "0.015}\n"
      "poses: {distance: [0.3, 0.6], tilt_max_deg: 40, roll_max_deg: 40, visibility: any}\n"
      "render: {spp: 4, blur_sigma: 0.8, noise_sigma: 2.0}\n");
  ChessboardDetectionOptions options;
  options.cols = 9;
  options.rows = 6;
  int cut = 0, cut_found = 0, whole = 0, whole_found = 0;
  double worst = 0;
  for (const FrameTruth& frame : truth.images) {
    const cv::Mat gray = cv::imread((dir / "set" / frame.cam1.file).string(), cv::IMREAD_GRAYSCALE);
    int in_view = 0;
    for (const auto& corner : frame.cam1.corners_px) {
      in_view +=
          corner && corner->x() > 0 && corner->y() > 0 && corner->x() < 800 && corner->y() < 600;
    }
    const ChessboardDetection detection = DetectChessboard(gray, options);
    (in_view == 54 ? whole : cut) += 1;
    if (!detection.found) {
      EXPECT_FALSE(detection.reason.empty()) << frame.cam1.file;
      std::cout << frame.cam1.file << " (" << in_view << " corners in view): " << detection.reason
                << "\n";
      continue;
    }
    (in_view == 54 ? whole_found : cut_found) += 1;
    EXPECT_EQ(detection.partial, in_view < 54) << frame.cam1.file;
    // A corner given another's place on the board would be a square
    // (tens of pixels) off; refined ones are hundredths off.
    for (size_t i = 0; i < detection.corners.size(); ++i) {
      if (detection.corners[i])
        worst = std::max(worst, (*detection.corners[i] - *frame.cam1.corners_px[i]).norm());
    }
  }
  std::cout << "whole boards found " << whole_found << " / " << whole << ", cut ones " << cut_found
            << " / " << cut << "; largest corner error " << worst << " px\n";
  EXPECT_EQ(whole_found, whole);
  EXPECT_LT(worst, 0.15);
  // Without the partial search none of the cut views is found; with it 6 of
  // 9 here (the other 3, cut at a corner of the image, fit the board in two
  // places, turned by 90 degrees: refused).
  EXPECT_GE(cut_found, cut / 2);
}

}  // namespace
}  // namespace portcal
