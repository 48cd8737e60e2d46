// What the live page draws: the frame with the corners found and the
// suggested pose, the coverage heat-map of the kept corners, and the map of
// the expected projection uncertainty; a rig's two cameras side by side.
// Pure drawing, no state.
#pragma once

#include <opencv2/core.hpp>

#include "pipelines/live/live_session.h"

namespace portcal {

// The frame (BGR, scaled to at most `max_width`): corners (green once held
// still long enough, yellow while held, red while moving), the suggested
// pose's outline (orange), and a line saying how far the target is from it.
cv::Mat DrawLiveOverlay(const LiveSnapshot& snapshot, const TargetShape& target, int max_width);

// The fraction of a 16 x 9 grid over (camera 1's) image whose cells hold a
// kept view's corner.
double CoverageFraction(const LiveSnapshot& snapshot);

// The kept views' corners over the image as a heat-map (smoothed counts,
// coloured) on the dimmed newest frame.
cv::Mat DrawCoverage(const LiveSnapshot& snapshot, int max_width);

// The expected projection uncertainty over the image (px, one sigma),
// coloured, with the grid's values written in; a gray image saying why when
// there is none yet.
cv::Mat DrawUncertainty(const LiveSnapshot& snapshot, int max_width);

}  // namespace portcal
