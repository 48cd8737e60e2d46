#include "pipelines/undistortion/virtual_pinhole.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

bool InsideImage(const Camera& camera, const Eigen::Vector2d& pixel) {
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= static_cast<double>(camera.width) &&
         pixel.y() <= static_cast<double>(camera.height);
}

// The extreme output coordinates of one side of the real image: `inner` is
// where the output stops showing only real pixels, `outer` where it has
// shown them all.
struct SideBounds {
  double inner = std::numeric_limits<double>::quiet_NaN();
  double outer = std::numeric_limits<double>::quiet_NaN();
};

// One side of the real image (x = const or y = const, `vertical`) sampled
// every few pixels, mapped to the output; `low` is the left or top side.
SideBounds BoundsOfSide(const VirtualPinhole& pinhole, bool vertical, bool low) {
  const Camera& camera = pinhole.source.camera;
  const double along = static_cast<double>(vertical ? camera.height : camera.width);
  const double across = low ? 0.0 : static_cast<double>(vertical ? camera.width : camera.height);
  const int axis = vertical ? 0 : 1;
  const int num_samples = std::max(16, static_cast<int>(along / 4));
  double min_value = std::numeric_limits<double>::infinity(), max_value = -min_value;
  for (int i = 0; i <= num_samples; ++i) {
    const double t = along * i / num_samples;
    const Eigen::Vector2d pixel =
        vertical ? Eigen::Vector2d(across, t) : Eigen::Vector2d(t, across);
    const std::optional<Eigen::Vector2d> output = pinhole.OutputPixel(pixel);
    if (!output) continue;
    min_value = std::min(min_value, (*output)[axis]);
    max_value = std::max(max_value, (*output)[axis]);
  }
  if (!std::isfinite(min_value)) {
    throw NumericalError("camera " + std::to_string(camera.camera_id) +
                         ": no pixel of the image's " +
                         (vertical ? (low ? "left" : "right") : (low ? "top" : "bottom")) +
                         " border has a ray; no pinhole can frame it");
  }
  // The low side's inner bound is its largest coordinate, the high side's
  // its smallest.
  return low ? SideBounds{max_value, min_value} : SideBounds{min_value, max_value};
}

// The output's extent along one axis, [low, high] in the first pinhole's
// coordinates, for `options`: blended between no blank pixels and all
// pixels kept, the size then held within the scale bounds around `centre`.
Eigen::Vector2d AxisExtent(const SideBounds& low, const SideBounds& high, double input_size,
                           double centre, const FieldOfViewOptions& options) {
  const double b = options.blank_pixels;
  double first = (1 - b) * low.inner + b * low.outer;
  double last = (1 - b) * high.inner + b * high.outer;
  const double scale = (last - first) / input_size;
  const double clipped = std::clamp(scale, options.min_scale, options.max_scale);
  if (!(scale > 0)) {
    first = centre - 0.5 * clipped * input_size;
    last = centre + 0.5 * clipped * input_size;
  } else if (clipped != scale) {
    const double k = clipped / scale;
    first = centre - (centre - first) * k;
    last = centre + (last - centre) * k;
  }
  return {first, last};
}

Eigen::Vector2d FocalLengths(const Camera& camera) {
  const std::vector<int> focal = CameraModelFocalLengthIdxs(camera.model_id);
  const double fx = camera.params[focal[0]];
  return {fx, focal.size() > 1 ? camera.params[focal[1]] : fx};
}

}  // namespace

std::optional<Eigen::Vector3d> VirtualPinhole::PointAtDepth(const Eigen::Vector2d& source_pixel,
                                                            double depth) const {
  const std::optional<Ray3d> ray = source.Unproject(source_pixel);
  if (!ray || !(ray->direction.z() > 1e-12)) return std::nullopt;
  const double t = (depth - ray->origin.z()) / ray->direction.z();
  if (!(t > 0)) return std::nullopt;
  return ray->origin + t * ray->direction;
}

std::optional<Eigen::Vector2d> VirtualPinhole::PinholePixel(
    const Eigen::Vector3d& point_in_cam) const {
  const Eigen::Vector3d point = pinhole_from_cam * point_in_cam;
  if (!(point.z() > 0)) return std::nullopt;
  const std::vector<double>& p = pinhole.params;  // fx, fy, cx, cy
  return Eigen::Vector2d(p[0] * point.x() / point.z() + p[2], p[1] * point.y() / point.z() + p[3]);
}

std::optional<Eigen::Vector2d> VirtualPinhole::SourcePixel(
    const Eigen::Vector2d& output_pixel) const {
  const std::vector<double>& p = pinhole.params;
  const Eigen::Vector3d ray_in_pinhole((output_pixel.x() - p[2]) / p[0],
                                       (output_pixel.y() - p[3]) / p[1], 1.0);
  const Eigen::Vector3d ray = pinhole_from_cam.transpose() * ray_in_pinhole;
  if (!(ray.z() > 1e-12)) return std::nullopt;
  return source.Project(ray * (design_depth / ray.z()));
}

std::optional<Eigen::Vector2d> VirtualPinhole::OutputPixel(
    const Eigen::Vector2d& source_pixel) const {
  const std::optional<Eigen::Vector3d> point = PointAtDepth(source_pixel, design_depth);
  if (!point) return std::nullopt;
  return PinholePixel(*point);
}

std::optional<double> VirtualPinhole::ErrorAtDepth(const Eigen::Vector2d& output_pixel,
                                                   double depth) const {
  const std::optional<Eigen::Vector2d> source_pixel = SourcePixel(output_pixel);
  if (!source_pixel || !InsideImage(source.camera, *source_pixel)) return std::nullopt;
  const std::optional<Eigen::Vector3d> point = PointAtDepth(*source_pixel, depth);
  if (!point) return std::nullopt;
  const std::optional<Eigen::Vector2d> seen = PinholePixel(*point);
  if (!seen) return std::nullopt;
  return (*seen - output_pixel).norm();
}

void FieldOfViewOptions::Check() const {
  if (!(blank_pixels >= 0 && blank_pixels <= 1)) {
    throw OptionError("--Undistort.blank_pixels", blank_pixels, "a value in [0, 1]");
  }
  if (!(min_scale > 0)) throw OptionError("--Undistort.min_scale", min_scale, "> 0");
  // Beyond 10x the input's side the output is all interpolation, and its
  // remap tables grow with the square.
  if (!(max_scale >= min_scale && max_scale <= 10)) {
    throw OptionError("--Undistort.max_scale", max_scale, "in [--Undistort.min_scale, 10]");
  }
}

VirtualPinhole FitVirtualPinhole(const HousedCamera& source, double design_depth,
                                 const Eigen::Matrix3d& pinhole_from_cam,
                                 const FieldOfViewOptions& options) {
  VirtualPinhole pinhole;
  pinhole.source = source;
  pinhole.pinhole_from_cam = pinhole_from_cam;
  pinhole.design_depth = design_depth;
  // First a pinhole of the camera's apparent focal lengths whose principal
  // point falls where the camera's does.
  const Eigen::Vector2d focal =
      FocalLengths(source.camera) / (source.housing ? source.housing->InAirFocalRatio() : 1.0);
  const Eigen::Vector2d principal(source.camera.PrincipalPointX(), source.camera.PrincipalPointY());
  pinhole.pinhole =
      Camera::FromModelName("PINHOLE", focal.x(), source.camera.width, source.camera.height);
  pinhole.pinhole.camera_id = source.camera.camera_id;
  pinhole.pinhole.params = {focal.x(), focal.y(), 0.0, 0.0};
  const std::optional<Eigen::Vector2d> centre = pinhole.OutputPixel(principal);
  if (!centre) {
    throw NumericalError("camera " + std::to_string(source.camera.camera_id) +
                         ": the principal point has no ray at the design depth");
  }
  pinhole.pinhole.params[2] = principal.x() - centre->x();
  pinhole.pinhole.params[3] = principal.y() - centre->y();
  // Then the extent of the camera's image in it, which sets the output size.
  const Eigen::Vector2d x_extent =
      AxisExtent(BoundsOfSide(pinhole, true, true), BoundsOfSide(pinhole, true, false),
                 static_cast<double>(source.camera.width), principal.x(), options);
  const Eigen::Vector2d y_extent =
      AxisExtent(BoundsOfSide(pinhole, false, true), BoundsOfSide(pinhole, false, false),
                 static_cast<double>(source.camera.height), principal.y(), options);
  double width = std::max(1.0, std::round(x_extent[1] - x_extent[0]));
  double height = std::max(1.0, std::round(y_extent[1] - y_extent[0]));
  std::vector<double>& p = pinhole.pinhole.params;
  p[2] -= x_extent[0];
  p[3] -= y_extent[0];
  const double largest = std::max(width, height);
  if (options.max_image_size > 0 && largest > options.max_image_size) {
    const double shrink = options.max_image_size / largest;
    for (double& value : p) value *= shrink;
    width = std::max(1.0, std::round(width * shrink));
    height = std::max(1.0, std::round(height * shrink));
  }
  pinhole.pinhole.width = static_cast<uint64_t>(width);
  pinhole.pinhole.height = static_cast<uint64_t>(height);
  return pinhole;
}

double HousingReach(const HousedCamera& camera) {
  if (!camera.housing) return 0.0;
  constexpr int kSteps = 16;
  double reach = 0.0;
  for (int i = 0; i <= kSteps; ++i) {
    for (int j = 0; j <= kSteps; ++j) {
      const Eigen::Vector2d pixel(static_cast<double>(camera.camera.width) * i / kSteps,
                                  static_cast<double>(camera.camera.height) * j / kSteps);
      const std::optional<Ray3d> ray = camera.Unproject(pixel);
      if (ray) reach = std::max(reach, ray->origin.z());
    }
  }
  return reach;
}

}  // namespace portcal
