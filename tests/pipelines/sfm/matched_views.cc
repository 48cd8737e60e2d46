#include "tests/pipelines/sfm/matched_views.h"

#include <random>

namespace portcal {
namespace testing {

MatchedViews MakeMatchedViews(const HousedCamera& truth, int num_images, double sigma_px,
                              uint32_t seed, ViewMotion motion) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, sigma_px);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 1500; ++i)
    points.emplace_back(0.45 * u(rng), 0.3 * u(rng), 0.8 + 0.2 * u(rng));
  MatchedViews scene;
  scene.truth = truth;
  scene.inputs.cameras[1] = truth;
  const Housing* housing = truth.housing ? &*truth.housing : nullptr;
  // Per image, per point: its keypoint index (or -1).
  std::vector<std::vector<int>> index(num_images, std::vector<int>(points.size(), -1));
  for (int v = 0; v < num_images; ++v) {
    Eigen::Matrix3d R;
    Eigen::Vector3d centre;
    if (motion == ViewMotion::kOrbit) {
      const double angle = 0.35 * (v - 0.5 * (num_images - 1)) / num_images;
      R = Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2 * u(rng), 1, 0.1 * u(rng)).normalized())
              .toRotationMatrix();
      // Orbiting the cloud's centre, looking at it.
      const Eigen::Vector3d target(0, 0, 0.8);
      centre = target - R.transpose() * target + Eigen::Vector3d(0, 0.03 * u(rng), 0);
    } else if (motion == ViewMotion::kGeneral) {
      // Turned up to ~11 deg about any axis, moved up to 0.15 m: the axes
      // pass the cloud at different points and distances.
      R = Eigen::AngleAxisd(0.2 * u(rng),
                            Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)).normalized())
              .toRotationMatrix();
      centre = Eigen::Vector3d(0.15 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
    } else {
      R = Eigen::Matrix3d::Identity();  // straight ahead, 4 cm a view
      centre = Eigen::Vector3d(0, 0, -0.04 * v);
    }
    SfmImage image;
    image.image_id = static_cast<image_t>(v + 1);
    image.name = "v" + std::to_string(v);
    image.camera_id = 1;
    for (size_t p = 0; p < points.size(); ++p) {
      const auto pixel = ProjectPoint(truth.camera, housing, R * (points[p] - centre));
      if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > truth.camera.width ||
          pixel->y() > truth.camera.height) {
        continue;
      }
      index[v][p] = static_cast<int>(image.keypoints.size());
      image.keypoints.push_back(*pixel + Eigen::Vector2d(noise(rng), noise(rng)));
    }
    image.correspondences.resize(image.keypoints.size());
    scene.inputs.images[image.image_id] = std::move(image);
  }
  for (int a = 0; a < num_images; ++a) {
    for (int b = a + 1; b < num_images; ++b) {
      int count = 0;
      for (size_t p = 0; p < points.size(); ++p) {
        if (index[a][p] < 0 || index[b][p] < 0) continue;
        scene.inputs.images[a + 1].correspondences[index[a][p]].push_back(
            {static_cast<image_t>(b + 1), static_cast<point2D_t>(index[b][p])});
        scene.inputs.images[b + 1].correspondences[index[b][p]].push_back(
            {static_cast<image_t>(a + 1), static_cast<point2D_t>(index[a][p])});
        ++count;
      }
      scene.inputs.pair_inliers[ImagePairToPairId(a + 1, b + 1)] = count;
    }
  }
  return scene;
}

}  // namespace testing
}  // namespace portcal
