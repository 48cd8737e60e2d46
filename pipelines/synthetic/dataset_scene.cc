#include "pipelines/synthetic/dataset_scene.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {

Clutter MakeClutter(const DatasetConfig& config) {
  Clutter clutter;
  const double d = config.clutter_distance_m;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  const Camera& camera = config.camera;
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(camera.width, 0), Eigen::Vector2d(0, camera.height),
        Eigen::Vector2d(camera.width, camera.height)}) {
    const auto ray = UnprojectPixel(camera, config.housing ? &*config.housing : nullptr, pixel);
    const Eigen::Vector3d p =
        ray ? Eigen::Vector3d(ray->origin +
                              (d - ray->origin.z()) / ray->direction.z() * ray->direction)
            : Eigen::Vector3d(d, d, d);
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y());
    y1 = std::max(y1, p.y());
  }
  // Wider for a stereo rig's second camera.
  const double pad =
      0.2 * (x1 - x0) + (config.stereo ? config.cam2_from_cam1.translation.norm() : 0.0);
  clutter.extent = Eigen::Vector4d(x0 - pad, x1 + pad, y0 - pad, y1 + pad);
  clutter.texel = d / config.camera.MeanFocalLength();
  const int cols =
      static_cast<int>(std::ceil((clutter.extent[1] - clutter.extent[0]) / clutter.texel));
  const int rows =
      static_cast<int>(std::ceil((clutter.extent[3] - clutter.extent[2]) / clutter.texel));
  const int scale = std::max(4, std::min(cols, rows) / 60);
  auto texture =
      std::make_shared<RasterTexture>(RandomShapesRaster(cols, rows, config.clutter_num_shapes,
                                                         config.clutter_seed, scale / 2, 3 * scale),
                                      clutter.extent[0], clutter.extent[2], clutter.texel);
  clutter.object = std::make_unique<FacesObject>(std::vector<Face>{{texture, Rigid3d(), -1.0}},
                                                 static_cast<float>(config.render.levels.back));
  clutter.cam_from_clutter = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, d));
  return clutter;
}

Scene BuildScene(const DatasetConfig& config, const HousedCamera& camera1, GroundTruth* truth) {
  Scene scene;
  if (config.survey) {
    scene.survey = PlanSurvey(config.camera, camera1.HousingOrNull(), config.survey_options);
    const SurveyPath& survey = scene.survey;
    const SurveyOptions& s = config.survey_options;
    const int cols = static_cast<int>(std::ceil((survey.area[1] - survey.area[0]) / s.texel_m));
    const int rows = static_cast<int>(std::ceil((survey.area[3] - survey.area[2]) / s.texel_m));
    const int shapes = static_cast<int>((survey.area[1] - survey.area[0]) *
                                        (survey.area[3] - survey.area[2]) * 600);
    auto texture = std::make_shared<RasterTexture>(
        RandomShapesRaster(cols, rows, shapes, s.texture_seed, 2, 10), survey.area[0],
        survey.area[2], s.texel_m);
    scene.seabed = std::make_unique<SeabedObject>(texture, s.roughness_m, s.relief_wavelength_m,
                                                  s.texture_seed + 1);
    scene.seabed_markers =
        PlaceSeabedMarkers(s.markers, *scene.seabed, survey.area, config.render.levels);
    truth->target.type = "seabed";
  } else {
    scene.target = BuildTarget(config.target, config.render.levels);
    truth->target = scene.target.description;
  }
  if (config.clutter) scene.clutter = MakeClutter(config);
  return scene;
}

// A target view camera 1 sees; with a rig, resampled until camera 2 sees
// the target too.
Rigid3d SampleRigView(const DatasetConfig& config, const Scene& scene, const HousedCamera& camera1,
                      const HousedCamera& camera2, const std::vector<Eigen::Vector3d>& check_points,
                      std::mt19937_64* rng) {
  for (int attempt = 0;; ++attempt) {
    const Rigid3d cam_from_target =
        SampleTargetView(config.camera, camera1.HousingOrNull(), check_points, scene.target.center,
                         scene.target.front_normal, config.poses, rng);
    if (!config.stereo) return cam_from_target;
    bool seen = true;
    const double margin = config.poses.border_margin_px;
    for (const Eigen::Vector3d& p : check_points) {
      const auto pixel = camera2.Project(config.cam2_from_cam1 * cam_from_target * p);
      seen = seen && pixel && pixel->x() >= margin && pixel->y() >= margin &&
             pixel->x() <= config.camera2.width - margin &&
             pixel->y() <= config.camera2.height - margin;
    }
    if (seen) return cam_from_target;
    if (attempt > 200) {
      throw NumericalError(
          "stereo: no pose found where both cameras see the target; "
          "check stereo.cam2_from_cam1 and poses.distance");
    }
  }
}

}  // namespace portcal
