// The pinhole camera that stands in for a real one (lens distortion, and a
// housing's refraction) in the tools that take only pinholes: COLMAP's
// dense stages, OpenMVS, splatting trainers, SLAM systems.
//
// In air the stand-in is exact: a pixel's ray is a direction from the
// camera centre, and the pinhole's ray through the output pixel is the
// same direction. Behind a port the rays in water do not meet in one
// point (a flat port; a dome whose centre is off the camera's), so no
// pinhole is exact: the undistorted image shows, at an output pixel, what
// the real camera sees of the point at the *design depth* on the
// pinhole's ray. A point at another depth on that ray is seen elsewhere,
// and ErrorAtDepth says by how many output pixels.
//
// Depth is z in the camera frame (metres), the distance of a plane facing
// the camera: a seabed below a downward-looking camera is at one depth.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "colmap_ext/camera/housed_camera.h"

namespace portcal {

struct VirtualPinhole {
  HousedCamera source;  // the exact model of the real camera
  Camera pinhole;       // PINHOLE (fx, fy, cx, cy) and the output size
  // Rotation of the pinhole's frame from the real camera's (identity but
  // for rectified stereo pairs); both share the camera centre.
  Eigen::Matrix3d pinhole_from_cam = Eigen::Matrix3d::Identity();
  // Metres, > 0. Any value in air (every depth maps alike there).
  double design_depth = 1.0;

  // The point at depth `depth` on the ray of `source_pixel` (in water
  // behind a port), in the real camera's frame; nullopt where the pixel
  // has no ray or its ray does not reach that depth.
  std::optional<Eigen::Vector3d> PointAtDepth(const Eigen::Vector2d& source_pixel,
                                              double depth) const;
  // A point in the real camera's frame -> the pinhole's pixel (COLMAP's
  // convention); nullopt behind the pinhole.
  std::optional<Eigen::Vector2d> PinholePixel(const Eigen::Vector3d& point_in_cam) const;
  // The remap table's entry: output pixel -> the real camera's pixel that
  // shows the design-depth point of the pinhole's ray (exact refraction).
  std::optional<Eigen::Vector2d> SourcePixel(const Eigen::Vector2d& output_pixel) const;
  // Where the undistorted image shows what the real camera sees at
  // `source_pixel` (a keypoint's new place): its design-depth point.
  std::optional<Eigen::Vector2d> OutputPixel(const Eigen::Vector2d& source_pixel) const;
  // How far from `output_pixel` the pinhole projects the point at `depth`
  // that the undistorted image shows there (output pixels); nullopt where
  // the output pixel shows nothing of the real image.
  std::optional<double> ErrorAtDepth(const Eigen::Vector2d& output_pixel, double depth) const;
};

// How the output's field of view and size are chosen (COLMAP's
// image_undistorter's options, with its defaults).
struct FieldOfViewOptions {
  // 0: no blank pixels (the output shows only what the camera saw); 1: every
  // pixel of the camera is kept (blank corners); in between, a blend.
  double blank_pixels = 0.0;
  // Bounds of the output size relative to the input's.
  double min_scale = 0.2;
  double max_scale = 2.0;
  // Largest output side in pixels (the focal lengths scale with it); <= 0:
  // no limit.
  int max_image_size = -1;

  void Check() const;  // throws OptionError naming --Undistort.*
};

// The virtual pinhole of `source` at `design_depth`, rotated by
// `pinhole_from_cam`: focal lengths those the camera has behind its
// housing near the axis (in air: its own), the principal point where the
// camera's falls, and an output size that frames the camera's image as
// `options` ask. Throws NumericalError when the camera's border has no rays.
VirtualPinhole FitVirtualPinhole(const HousedCamera& source, double design_depth,
                                 const Eigen::Matrix3d& pinhole_from_cam,
                                 const FieldOfViewOptions& options);

// The largest depth (z, metres) the housing's outer surface reaches over
// the image's rays: a design depth or a depth range must lie beyond it.
// 0 in air.
double HousingReach(const HousedCamera& camera);

}  // namespace portcal
