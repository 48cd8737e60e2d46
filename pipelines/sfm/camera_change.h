// How far a change of a camera's intrinsics and housing moves the image of
// the scene. The mapper refines them while the model grows and stops once a
// refinement no longer moves the image (see
// IncrementalMapperOptions::ba_calibration_settled_px).
#pragma once

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

// The largest distance, in pixels, between the pixels of a grid over the
// image and where `after` sees the points that `before` sees there at
// `depth_m` (metres along the optical axis). Infinity where a grid pixel
// has no ray under `before` or its point no image under `after`.
double MaxImageShiftPx(const HousedCamera& before, const HousedCamera& after, double depth_m);

// The median depth (metres along the optical axis) of the model's points
// in the images that see them, over up to `max_samples` points; 0 if there
// are none.
double MedianSceneDepth(const Reconstruction& r, int max_samples = 10000);

}  // namespace portcal
