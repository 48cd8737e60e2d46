// portcal's camera and housing models against the independent ray tracer
// that rendered ../shared/datasets/rendered: projecting each set's corners
// with its ground-truth pose, camera and housing must give the ground-truth
// pixels to the last digit that matters (1e-6 px; the files carry ~16
// significant digits).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

Camera CameraFromYaml(const YAML::Node& node) {
  Camera camera;
  camera.model_id = CameraModelNameToId(node["model"].as<std::string>());
  camera.width = node["width"].as<int>();
  camera.height = node["height"].as<int>();
  camera.params = node["params"].as<std::vector<double>>();
  camera.Validate("ground_truth.yaml camera");
  return camera;
}

std::optional<Housing> HousingFromYaml(const YAML::Node& node) {
  if (!node || node.IsNull()) return std::nullopt;
  return Housing::FromName(node["model"].as<std::string>(),
                           node["params"].as<std::vector<double>>(), "ground_truth.yaml housing");
}

Rigid3d PoseFromYaml(const YAML::Node& node) {
  const auto q = node["rotation_wxyz"].as<std::vector<double>>();
  const auto t = node["translation"].as<std::vector<double>>();
  return Rigid3d(QuaternionFromWxyz(Eigen::Vector4d(q[0], q[1], q[2], q[3])),
                 Eigen::Vector3d(t[0], t[1], t[2]));
}

// Max |projected - ground truth| over all corners of one camera's images.
double MaxCornerError(const Camera& camera, const std::optional<Housing>& housing,
                      const std::vector<Eigen::Vector3d>& corners,
                      const std::vector<std::pair<Rigid3d, YAML::Node>>& views, int* num_checked) {
  double max_error = 0;
  for (const auto& [cam_from_target, corners_px] : views) {
    for (size_t i = 0; i < corners.size(); ++i) {
      const auto expected = corners_px[i].as<std::vector<double>>();
      const std::optional<Eigen::Vector2d> pixel =
          ProjectPoint(camera, housing ? &*housing : nullptr, cam_from_target * corners[i]);
      EXPECT_TRUE(pixel.has_value());
      if (!pixel) continue;
      max_error = std::max(max_error, (*pixel - Eigen::Vector2d(expected[0], expected[1])).norm());
      ++*num_checked;
    }
  }
  return max_error;
}

class GroundTruthTest : public ::testing::TestWithParam<std::string> {};

TEST_P(GroundTruthTest, ModelsReproduceTheRenderersPixels) {
  PORTCAL_REQUIRE_SHARED(shared);
  const auto path = shared / "datasets/rendered" / GetParam() / "ground_truth.yaml";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  const YAML::Node root = YAML::LoadFile(path.string());
  std::vector<Eigen::Vector3d> corners;
  for (const auto& c : root["target"]["corners_3d"]) {
    const auto v = c.as<std::vector<double>>();
    corners.emplace_back(v[0], v[1], v[2]);
  }
  const Camera camera1 = CameraFromYaml(root["camera"]);
  const std::optional<Housing> housing1 = HousingFromYaml(root["housing"]);
  const bool stereo = root["stereo"] && !root["stereo"].IsNull();
  std::vector<std::pair<Rigid3d, YAML::Node>> views1, views2;
  for (const auto& image : root["images"]) {
    if (stereo) {
      views1.emplace_back(PoseFromYaml(image["cam1"]["cam_from_target"]),
                          image["cam1"]["corners_px"]);
      views2.emplace_back(PoseFromYaml(image["cam2"]["cam_from_target"]),
                          image["cam2"]["corners_px"]);
    } else {
      views1.emplace_back(PoseFromYaml(image["cam_from_target"]), image["corners_px"]);
    }
  }
  int num_checked = 0;
  EXPECT_LT(MaxCornerError(camera1, housing1, corners, views1, &num_checked), 1e-6);
  if (stereo) {
    const YAML::Node& s = root["stereo"];
    const Camera camera2 = CameraFromYaml(s["camera2"]);
    const std::optional<Housing> housing2 = HousingFromYaml(s["housing2"]);
    EXPECT_LT(MaxCornerError(camera2, housing2, corners, views2, &num_checked), 1e-6);
    // cam2_from_target = cam2_from_cam1 * cam1_from_target, as the file states.
    const Rigid3d cam2_from_cam1 = PoseFromYaml(s["cam2_from_cam1"]);
    for (size_t i = 0; i < views1.size(); ++i) {
      const Rigid3d composed = cam2_from_cam1 * views1[i].first;
      EXPECT_LT((composed.translation - views2[i].first.translation).norm(), 1e-12);
      EXPECT_LT(composed.rotation.angularDistance(views2[i].first.rotation), 1e-12);
    }
  }
  EXPECT_GT(num_checked, 1000);
}

INSTANTIATE_TEST_SUITE_P(RenderedSets, GroundTruthTest,
                         ::testing::Values("chess_air_distorted", "chess_domeport",
                                           "chess_flatport", "chess_stereo_air"));

}  // namespace
}  // namespace portcal
