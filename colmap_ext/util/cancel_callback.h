// A Ceres iteration callback that ends a solve once the user asked to stop
// (CancelFlag, set by SIGINT): a bundle adjustment of a few thousand images
// runs for minutes between a stage's own checks, and a stop must come
// within a couple of seconds. The caller then calls
// CancelFlag::ThrowIfRequested() before reading the summary, so the abort
// is a Cancelled, not a failed solve.
#pragma once

#include <ceres/iteration_callback.h>

#include "colmap_ext/util/progress.h"

namespace portcal {

class CancelCallback : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return CancelFlag::Requested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};

}  // namespace portcal
