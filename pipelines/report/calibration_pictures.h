// The pictures of a calibration, each answering a question a person asks of
// it: is the image covered (coverage), is any view bad (per-view RMS), is
// the lens model right (residual vectors: a pattern means no), how far can
// a projection be trusted (uncertainty map). geometry_pictures.h draws the
// housing, the rig and the reconstruction.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

// Target views at their calibrated poses (matched by image name; a view
// without a calibrated pose is left out).
struct ViewsAtPoses {
  HousedCamera camera;
  std::vector<CalibrationView> views;
  std::vector<CalibratedView> calibrated;
  std::optional<Eigen::Vector2d> board_warp;  // metres, when fitted
};

struct PointResidual {
  Eigen::Vector2d observed;  // pixel
  Eigen::Vector2d residual;  // observed - predicted, px
  int view = 0;              // index into ViewsAtPoses::calibrated
  bool dropped = false;      // its view was left out of the solve
};

std::vector<PointResidual> ResidualsAtPoses(const ViewsAtPoses& views);

// Where the observations lie: counts per cell over the image.
cv::Mat CoveragePicture(const Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                        const std::string& what);

// Each view's RMS; outliers red, dropped grey; the residual sigma dashed.
cv::Mat PerViewRmsPicture(const std::vector<CalibratedView>& views, double residual_sigma_px,
                          const std::string& title);

// The residuals as arrows from their observations, magnified, coloured by
// view (mrcal's residual field); dropped views' left out.
cv::Mat ResidualVectorsPicture(const Camera& camera, const std::vector<PointResidual>& residuals,
                               int num_views, const std::string& title);

// The expected projection uncertainty (px, 1 sigma, mrcal's mean-frames
// measure) over the image at the kept views' median depth and at infinity,
// from the information of the kept views at `pixel_sigma_px`
// (guidance/projection_uncertainty.h): of the intrinsics not held (and the
// board warp, when fitted), or with `housing_calibration` of the housing's
// refined parameters.
ProjectionUncertaintyGrid ProjectionUncertaintyOfViews(const ViewsAtPoses& views,
                                                       bool housing_calibration,
                                                       const std::vector<int>& fixed,
                                                       double pixel_sigma_px);

// The grid's map at the working distance (or at infinity) as a heat map.
cv::Mat UncertaintyPicture(const ProjectionUncertaintyGrid& grid, int width, int height,
                           bool at_infinity = false);

}  // namespace portcal
