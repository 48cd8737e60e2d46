// Where the camera is when it takes each picture: random well-spread views of
// a target, or a lawnmower survey over a seabed.
#pragma once

#include <Eigen/Core>
#include <random>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/synthetic/seabed_markers.h"

namespace portcal {

struct ViewSamplingOptions {
  double distance_min_m = 0.4;     // camera centre to target centre, > 0
  double distance_max_m = 1.4;     // >= distance_min_m
  double tilt_max_deg = 45;        // target normal vs line of sight, [0, 89]
  double roll_max_deg = 30;        // about the line of sight, [0, 180]
  double border_margin_px = 10;    // check points this far inside the image, >= 0
  double max_view_angle_deg = 75;  // at every check point, (0, 90]
  // full: every check point inside the image; markers: every marker corner;
  // any: the target centre only.
  std::string visibility = "full";
  int max_tries = 5000;
  void Check() const;
};

// A cam_from_target pose meeting the options. `check_points` and `center`
// are in the target frame; `front_normal` (target frame) points from the
// print towards the viewer. Throws NumericalError naming the constraint when
// no pose is found within max_tries.
Rigid3d SampleTargetView(const Camera& camera, const Housing* housing,
                         const std::vector<Eigen::Vector3d>& check_points,
                         const Eigen::Vector3d& center, const Eigen::Vector3d& front_normal,
                         const ViewSamplingOptions& options, std::mt19937_64* rng);

struct SurveyOptions {
  double height_m = 2.0;             // above the mean seabed, > 0
  double speed_m_s = 0.5;            // along track, > 0
  double frame_rate_hz = 1.0;        // > 0
  double side_overlap = 0.6;         // between neighbouring lines, [0, 0.95]
  double line_length_m = 10.0;       // > 0
  int num_images = 100;              // >= 1
  double roughness_m = 0.1;          // standard deviation of the relief, >= 0
  double relief_wavelength_m = 2.0;  // > 0
  double texel_m = 0.004;            // seabed texture resolution, > 0
  uint64_t texture_seed = 21;
  // Noise of the navigation positions written beside the images
  // (navigation.txt, per axis), metres: a DVL-aided INS over a short survey.
  double navigation_sigma_m = 0.02;
  SeabedMarkerOptions markers;  // survey.markers: ArUco plates near the start (none by default)
  void Check() const;
};

struct SurveyPath {
  std::vector<Rigid3d> cam_from_world;  // world: seabed frame, z up
  double line_spacing_m = 0;
  double frame_spacing_m = 0;
  double footprint_width_m = 0;
  Eigen::Vector4d area = Eigen::Vector4d::Zero();  // [x0, x1, y0, y1] the cameras see
};

// Lines along +x / -x (alternating), spaced for the side overlap of the
// camera's footprint (computed through the housing) at the given height;
// frames every speed / frame_rate metres; camera looking straight down, x
// along the track.
SurveyPath PlanSurvey(const Camera& camera, const Housing* housing, const SurveyOptions& options);

}  // namespace portcal
