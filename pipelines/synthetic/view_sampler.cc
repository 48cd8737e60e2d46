#include "pipelines/synthetic/view_sampler.h"

#include <Eigen/Geometry>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool InsideImage(const Camera& camera, const Eigen::Vector2d& pixel, double margin) {
  return pixel.x() >= margin && pixel.y() >= margin && pixel.x() <= camera.width - margin &&
         pixel.y() <= camera.height - margin;
}

}  // namespace

void ViewSamplingOptions::Check() const {
  if (!(distance_min_m > 0)) throw OptionError("poses.distance[0]", distance_min_m, "> 0 m");
  if (!(distance_max_m >= distance_min_m)) {
    throw OptionError("poses.distance[1]", distance_max_m, ">= distance[0]");
  }
  if (!(tilt_max_deg >= 0 && tilt_max_deg <= 89)) {
    throw OptionError("poses.tilt_max_deg", tilt_max_deg, "[0, 89]");
  }
  if (!(roll_max_deg >= 0 && roll_max_deg <= 180)) {
    throw OptionError("poses.roll_max_deg", roll_max_deg, "[0, 180]");
  }
  if (!(border_margin_px >= 0)) {
    throw OptionError("poses.border_margin_px", border_margin_px, ">= 0");
  }
  if (!(max_view_angle_deg > 0 && max_view_angle_deg <= 90)) {
    throw OptionError("poses.max_view_angle_deg", max_view_angle_deg, "(0, 90]");
  }
  if (visibility != "full" && visibility != "markers" && visibility != "any") {
    throw OptionError("poses.visibility", visibility, "full, markers or any");
  }
  if (max_tries < 1) throw OptionError("poses.max_tries", max_tries, ">= 1");
}

Rigid3d SampleTargetView(const Camera& camera, const Housing* housing,
                         const std::vector<Eigen::Vector3d>& check_points,
                         const Eigen::Vector3d& center, const Eigen::Vector3d& front_normal,
                         const ViewSamplingOptions& options, std::mt19937_64* rng) {
  options.Check();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double margin = options.border_margin_px;
  // Target frame -> "facing the camera" orientation: the front normal onto
  // -z (towards the camera), with the smallest rotation.
  const Eigen::Quaterniond facing =
      Eigen::Quaterniond::FromTwoVectors(front_normal.normalized(), -Eigen::Vector3d::UnitZ());
  int rejected_projection = 0, rejected_angle = 0;
  for (int attempt = 0; attempt < options.max_tries; ++attempt) {
    // The target centre on the ray of a random pixel, at a random distance.
    // One draw per statement: the order in which a call's arguments are
    // evaluated is unspecified (gcc and clang differ), and a seed must make
    // the same set whichever compiler built the renderer. Row before column:
    // the order gcc's builds drew them in, which made the sets measured so far.
    const double row_fraction = unit(*rng);
    const double column_fraction = unit(*rng);
    const Eigen::Vector2d pixel(margin + column_fraction * (camera.width - 2 * margin),
                                margin + row_fraction * (camera.height - 2 * margin));
    const std::optional<Ray3d> ray = UnprojectPixel(camera, housing, pixel);
    if (!ray) continue;
    const double distance =
        options.distance_min_m + unit(*rng) * (options.distance_max_m - options.distance_min_m);
    const Eigen::Vector3d center_in_cam = ray->origin + distance * ray->direction;
    // Front normal: towards the camera, tilted by up to tilt_max (uniform on
    // the spherical cap), then a roll about the line of sight.
    const Eigen::Vector3d to_camera = -center_in_cam.normalized();
    const double cos_tilt = 1 - unit(*rng) * (1 - std::cos(options.tilt_max_deg * kDeg));
    const double azimuth = 2 * M_PI * unit(*rng);
    Eigen::Vector3d a = to_camera.unitOrthogonal(), b = to_camera.cross(a);
    const double sin_tilt = std::sqrt(std::max(0.0, 1 - cos_tilt * cos_tilt));
    const Eigen::Vector3d normal =
        cos_tilt * to_camera + sin_tilt * (std::cos(azimuth) * a + std::sin(azimuth) * b);
    const double roll = (2 * unit(*rng) - 1) * options.roll_max_deg * kDeg;
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond::FromTwoVectors(-Eigen::Vector3d::UnitZ(), normal) *
        Eigen::Quaterniond(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ())) * facing;
    const Rigid3d cam_from_target(rotation, center_in_cam - rotation * center);

    bool ok = true;
    const std::vector<Eigen::Vector3d> points =
        options.visibility == "any" ? std::vector<Eigen::Vector3d>{center} : check_points;
    for (const Eigen::Vector3d& point : points) {
      const Eigen::Vector3d in_cam = cam_from_target * point;
      const auto projected = ProjectPoint(camera, housing, in_cam);
      if (!projected || !InsideImage(camera, *projected, margin)) {
        ok = false;
        ++rejected_projection;
        break;
      }
      // Not at grazing incidence: the line of sight vs the print's normal.
      if (-in_cam.normalized().dot(normal) < std::cos(options.max_view_angle_deg * kDeg)) {
        ok = false;
        ++rejected_angle;
        break;
      }
    }
    if (ok) return cam_from_target;
  }
  throw NumericalError("could not place the target in " + std::to_string(options.max_tries) +
                       " tries (" + std::to_string(rejected_projection) +
                       " views left the image or its border margin, " +
                       std::to_string(rejected_angle) +
                       " exceeded max_view_angle_deg): widen poses.distance or relax "
                       "visibility");
}

void SurveyOptions::Check() const {
  if (!(height_m > 0)) throw OptionError("survey.height", height_m, "> 0 m");
  if (!(speed_m_s > 0)) throw OptionError("survey.speed", speed_m_s, "> 0 m/s");
  if (!(frame_rate_hz > 0)) throw OptionError("survey.frame_rate", frame_rate_hz, "> 0 Hz");
  if (!(side_overlap >= 0 && side_overlap <= 0.95)) {
    throw OptionError("survey.side_overlap", side_overlap, "[0, 0.95]");
  }
  if (!(line_length_m > 0)) throw OptionError("survey.line_length", line_length_m, "> 0 m");
  if (num_images < 1) throw OptionError("survey.num_images", num_images, ">= 1");
  if (!(roughness_m >= 0)) throw OptionError("survey.roughness", roughness_m, ">= 0 m");
  if (!(relief_wavelength_m > 0)) {
    throw OptionError("survey.relief_wavelength", relief_wavelength_m, "> 0 m");
  }
  if (!(texel_m > 0)) throw OptionError("survey.texel", texel_m, "> 0 m");
  if (!(navigation_sigma_m >= 0)) {
    throw OptionError("survey.navigation_sigma", navigation_sigma_m, ">= 0 m");
  }
  markers.Check();
}

SurveyPath PlanSurvey(const Camera& camera, const Housing* housing, const SurveyOptions& options) {
  options.Check();
  SurveyPath path;
  // Footprint across the track (camera y, world y): from the rays of the
  // image's left and right edges... the camera's x is along the track, so
  // the cross-track extent comes from the top and bottom rows.
  double y_min = 1e300, y_max = -1e300, x_min = 1e300, x_max = -1e300;
  for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(camera.width / 2.0, 0.5),
                                       Eigen::Vector2d(camera.width / 2.0, camera.height - 0.5),
                                       Eigen::Vector2d(0.5, camera.height / 2.0),
                                       Eigen::Vector2d(camera.width - 0.5, camera.height / 2.0)}) {
    const auto ray = UnprojectPixel(camera, housing, pixel);
    if (!ray || ray->direction.z() <= 0) {
      throw InputError("survey: the camera's image edges have no rays towards the seabed");
    }
    const Eigen::Vector3d on_bed =
        ray->origin + (options.height_m - ray->origin.z()) / ray->direction.z() * ray->direction;
    x_min = std::min(x_min, on_bed.x());
    x_max = std::max(x_max, on_bed.x());
    y_min = std::min(y_min, on_bed.y());
    y_max = std::max(y_max, on_bed.y());
  }
  path.footprint_width_m = y_max - y_min;
  path.line_spacing_m = path.footprint_width_m * (1 - options.side_overlap);
  path.frame_spacing_m = options.speed_m_s / options.frame_rate_hz;
  const int frames_per_line =
      std::max(1, static_cast<int>(std::floor(options.line_length_m / path.frame_spacing_m)) + 1);
  // Camera looking down: cam z = -world z; cam x = +-world x (track);
  // cam y = cam z x cam x.
  for (int i = 0; i < options.num_images; ++i) {
    const int line = i / frames_per_line, k = i % frames_per_line;
    const bool forward = line % 2 == 0;
    const double x =
        forward ? k * path.frame_spacing_m : (frames_per_line - 1 - k) * path.frame_spacing_m;
    const double y = line * path.line_spacing_m;
    Eigen::Matrix3d world_from_cam;
    const Eigen::Vector3d cam_x(forward ? 1.0 : -1.0, 0.0, 0.0);
    const Eigen::Vector3d cam_z = -Eigen::Vector3d::UnitZ();
    world_from_cam << cam_x, cam_z.cross(cam_x), cam_z;
    const Eigen::Quaterniond rotation(world_from_cam.transpose());
    const Eigen::Vector3d position(x, y, options.height_m);
    path.cam_from_world.emplace_back(rotation, -(rotation * position));
  }
  const int num_lines = (options.num_images - 1) / frames_per_line + 1;
  const double half_x = 0.5 * std::max(x_max - x_min, y_max - y_min) + 0.5;
  path.area = Eigen::Vector4d(-half_x, (frames_per_line - 1) * path.frame_spacing_m + half_x,
                              -half_x, (num_lines - 1) * path.line_spacing_m + half_x);
  return path;
}

}  // namespace portcal
