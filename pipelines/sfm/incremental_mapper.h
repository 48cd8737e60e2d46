// The steps of incremental structure-from-motion on refracted rays
// (Schoenberger and Frahm, "Structure-from-motion revisited", CVPR 2016,
// with every observation a ray in water as in She et al., "Refractive
// COLMAP", IROS 2024): the next images to try, registration by generalized
// absolute pose (gp3p in RANSAC), triangulation of the new rays, local and
// global refractive bundle adjustment, outlier filtering. With no housing it
// is ordinary SfM through the same code. When to take which step (initial
// pairs, restarts, when to refine the calibration) is the pipeline's
// (incremental_pipeline.h), as COLMAP splits sfm/incremental_mapper from
// controllers/incremental_pipeline.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/global_adjustment.h"
#include "pipelines/sfm/incremental_mapper_options.h"

namespace portcal {

// What a global adjustment did, for the pipeline's bookkeeping.
struct GlobalAdjustmentOutcome {
  bool refined_intrinsics = false;  // asked and allowed at this model size
  bool implausible = false;         // the intrinsics came out bogus and were held
  BundleAdjustmentOptions ba;       // as last solved
  ceres::Solver::Summary summary;   // of the main solve
  std::map<camera_t, HousedCamera> cameras_before;
};

class IncrementalMapper {
 public:
  IncrementalMapper(const SfmInputs& inputs, const std::map<camera_t, HousedCamera>& cameras,
                    const IncrementalMapperOptions& options)
      : inputs_(inputs), cameras_(cameras), options_(options) {}

  // Forgets what it tracked about the model grown before.
  void BeginModel();
  // The model's images are taken: no later model registers them.
  void EndModel(const Reconstruction& r);
  // Images registered in earlier models.
  const std::set<image_t>& used() const { return used_; }
  // The marker corners the last global adjustment left, dropped (the model
  // they belong to was undone).
  void ForgetMarkerCorners() { marker_corners_.clear(); }

  // Unregistered images that see enough of the model's points, most first
  // (none that failed since the model last grew).
  std::vector<image_t> NextImages(const Reconstruction& r) const;
  // Registers the image and links its keypoints to the points they see;
  // remembers a failure until an image registers.
  bool RegisterImage(Reconstruction* r, image_t image_id);
  // Continues tracks and triangulates new points of the image; returns the
  // points created.
  int Triangulate(Reconstruction* r, image_t image_id);
  // Drops observations beyond the reprojection bound and points whose rays
  // meet at too small an angle (of `images`' points; all when null).
  int Filter(Reconstruction* r, const std::set<image_t>* images);
  // The image and the images sharing the most points with it, adjusted.
  void LocalAdjust(Reconstruction* r, image_t image_id);
  // Adjusts the whole model (intrinsics and housing when asked and the model
  // is large enough), undoing intrinsics that come out implausible; does not
  // filter.
  GlobalAdjustmentOutcome AdjustGlobally(Reconstruction* r, bool refine_intrinsics,
                                         AdjustmentEnd end);

 private:
  double FocalOf(image_t image_id) const {
    return cameras_.at(inputs_.images.at(image_id).camera_id).camera.MeanFocalLength();
  }
  bool Register(Reconstruction* r, image_t image_id);
  // The housing's adjustments before the joint one (see AdjustGlobally).
  void AdjustHousingFirst(Reconstruction* r, const BundleAdjustmentOptions& ba,
                          std::vector<MarkerCorner>* markers);

  const SfmInputs& inputs_;
  const std::map<camera_t, HousedCamera>& cameras_;
  const IncrementalMapperOptions& options_;
  std::set<image_t> used_;    // registered in an earlier model
  std::set<image_t> failed_;  // failed to register since the model last grew
  // A global adjustment refining the housing has converged (off its bounds)
  // in the current model.
  bool port_converged_ = false;
  // The markers' corners as the last global adjustment left them.
  std::vector<MarkerCorner> marker_corners_;
  int num_implausible_said_ = 0;  // warnings of implausible intrinsics so far
};

}  // namespace portcal
