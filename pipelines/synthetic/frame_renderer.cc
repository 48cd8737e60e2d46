#include "pipelines/synthetic/frame_renderer.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "colmap_ext/housing/housing.h"

namespace portcal {
namespace {

// An opaque dark plate between the camera and a random part of the target.
std::unique_ptr<SceneObject> MakeOccluder(const BuiltTarget& target, const Rigid3d& cam_from_target,
                                          double fraction, std::mt19937_64* rng,
                                          Rigid3d* cam_from_occluder) {
  std::uniform_real_distribution<double> unit(0, 1);
  const auto& points = target.outline_points;
  // One draw per statement (the operands' order is the compiler's; this is
  // gcc's): the outline point, then how far towards it from the centre.
  const Eigen::Vector3d& toward =
      points[static_cast<size_t>(unit(*rng) * points.size()) % points.size()];
  const double reach = unit(*rng);
  const Eigen::Vector3d anchor_in_target = target.center + reach * (toward - target.center);
  double size = 0;
  for (const auto& p : points) size = std::max(size, 2 * (p - target.center).norm());
  const double along = 0.55;
  const Eigen::Vector3d anchor = along * (cam_from_target * anchor_in_target);
  const double side = std::sqrt(fraction) * size * along;
  const int n = 16;
  cv::Mat raster(n, n, CV_8UC1);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c)
      raster.at<uint8_t>(r, c) = static_cast<uint8_t>(20 + 40 * unit(*rng));
  }
  auto texture = std::make_shared<RasterTexture>(raster, -side / 2, -side / 2, side / n);
  *cam_from_occluder = Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(2 * M_PI * unit(*rng), Eigen::Vector3d::UnitZ())),
      anchor);
  return std::make_unique<FacesObject>(std::vector<Face>{{texture, Rigid3d(), -1.0}}, 40.0f);
}

// Ground truth of one camera's view of the target.
ImageTruth TargetTruth(const Camera& camera, const Housing* housing, const BuiltTarget& target,
                       const Rigid3d& cam_from_target, const std::vector<PlacedObject>& objects,
                       bool check_occlusion) {
  ImageTruth truth;
  truth.cam_from_target = cam_from_target;
  const auto inside = [&](const Eigen::Vector2d& p) {
    return p.x() >= 0 && p.y() >= 0 && p.x() <= camera.width && p.y() <= camera.height;
  };
  bool any_hidden = false;
  for (const Eigen::Vector3d& corner : target.description.corners_3d) {
    const Eigen::Vector3d in_cam = cam_from_target * corner;
    const std::optional<Eigen::Vector2d> pixel = ProjectPoint(camera, housing, in_cam);
    truth.corners_px.push_back(pixel);
    bool visible = pixel.has_value() && inside(*pixel);
    if (visible && check_occlusion) {
      // Visible if the pixel's ray hits the scene at the corner itself.
      const auto ray = UnprojectPixel(camera, housing, *pixel);
      Hit hit;
      visible = ray && IntersectScene(objects, ray->origin, ray->direction, &hit) &&
                (ray->origin + hit.t * ray->direction - in_cam).norm() < 1e-6;
    }
    any_hidden = any_hidden || !visible;
    truth.corners_visible.push_back(visible);
  }
  if (!any_hidden) truth.corners_visible.clear();
  for (const TargetMarker& marker : target.description.markers) {
    ImageTruth::Marker seen;
    seen.id = marker.id;
    bool projects = true;
    for (int k = 0; k < 4; ++k) {
      const auto pixel = ProjectPoint(camera, housing, cam_from_target * marker.corners[k]);
      if (!pixel) {
        projects = false;
        break;
      }
      seen.corners_px[k] = *pixel;
      seen.fully_inside = seen.fully_inside && inside(*pixel);
    }
    if (projects) truth.markers.push_back(seen);
  }
  return truth;
}

// The rig's motion as camera 2 sees it: for a small motion M of camera 1,
// camera 2 moves by T M T^-1 (T = cam2_from_cam1), whose rates are
// w2 = R w1 and v2 = R v1 - w2 x t.
ImageFormationOptions MotionInCamera2(ImageFormationOptions render, const Rigid3d& cam2_from_cam1) {
  const Eigen::Matrix3d rotation = cam2_from_cam1.rotation.toRotationMatrix();
  render.angular_velocity_rad_s = rotation * render.angular_velocity_rad_s;
  render.velocity_m_s = rotation * render.velocity_m_s -
                        render.angular_velocity_rad_s.cross(cam2_from_cam1.translation);
  return render;
}

}  // namespace

RenderedFrame FrameRenderer::Render(int frame, const std::string& name,
                                    const Rigid3d& cam_from_target,
                                    const ImageFormationOptions& render,
                                    std::mt19937_64* rng) const {
  std::vector<PlacedObject> objects;
  objects.push_back({config.survey ? static_cast<const SceneObject*>(scene.seabed.get())
                                   : scene.target.object.get(),
                     cam_from_target});
  if (scene.clutter)
    objects.push_back({scene.clutter->object.get(), scene.clutter->cam_from_clutter});
  if (scene.seabed_markers.object)
    objects.push_back({scene.seabed_markers.object.get(), cam_from_target});
  std::unique_ptr<SceneObject> occluder;
  std::uniform_real_distribution<double> unit(0, 1);
  if (!config.survey && unit(*rng) < config.occlusion_probability) {
    Rigid3d cam_from_occluder;
    occluder = MakeOccluder(scene.target, cam_from_target, config.occlusion_fraction, rng,
                            &cam_from_occluder);
    objects.push_back({occluder.get(), cam_from_occluder});
  }
  RenderedFrame rendered;
  FrameTruth& truth = rendered.truth;
  truth.frame = frame;
  const uint64_t noise_seed = config.seed * 1000003ULL + 2ULL * frame;
  rendered.image1 = RenderImage(rays1, objects, render, noise_seed);
  truth.cam1 = config.survey ? ImageTruth{}
                             : TargetTruth(config.camera, camera1.HousingOrNull(), scene.target,
                                           cam_from_target, objects, occluder != nullptr);
  truth.cam1.file = dir1 + "/" + name;
  truth.cam1.cam_from_target = cam_from_target;
  if (config.stereo) {
    std::vector<PlacedObject> objects2 = objects;
    for (PlacedObject& placed : objects2)
      placed.cam_from_object = config.cam2_from_cam1 * placed.cam_from_object;
    rendered.image2 = RenderImage(*rays2, objects2, MotionInCamera2(render, config.cam2_from_cam1),
                                  noise_seed + 1);
    const Rigid3d cam2_from_target = config.cam2_from_cam1 * cam_from_target;
    truth.cam2 = config.survey ? ImageTruth{}
                               : TargetTruth(config.camera2, camera2.HousingOrNull(), scene.target,
                                             cam2_from_target, objects2, occluder != nullptr);
    truth.cam2->file = dir2 + "/" + name;
    truth.cam2->cam_from_target = cam2_from_target;
  }
  return rendered;
}

}  // namespace portcal
