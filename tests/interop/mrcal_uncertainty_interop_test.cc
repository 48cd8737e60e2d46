// Projection uncertainty against mrcal's own: camera_calibrator writes its
// grid into calibration.yaml (projection_uncertainty) and its solve into
// camera.cameramodel; mrcal 2.2's projection_uncertainty(...,
// 'worstdirection-stdev') on that file, at the same pixels and points,
// must give the same numbers within 10 % at every cell, at the working
// distance and at infinity. On the shared real in-air set (OPENCV, the
// board's warp fitted, as the quickstart) and on the shared rendered one.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// mrcal at each pixel (COLMAP convention in the file; mrcal's is 0.5
// less) of the point at depth `depth` along its ray, and at infinity; one
// line "sigma_at_depth sigma_at_infinity" per pixel.
constexpr const char* kMrcalScript = R"(
import sys
import numpy as np
import mrcal
model = mrcal.cameramodel(sys.argv[1])
depth = float(sys.argv[2])
q = np.loadtxt(sys.argv[3], ndmin=2) - 0.5
v = mrcal.unproject(q, *model.intrinsics())
p = v / v[:, 2:3] * depth
near = mrcal.projection_uncertainty(p, model=model, what='worstdirection-stdev')
far = mrcal.projection_uncertainty(p, model=model, atinfinity=True, what='worstdirection-stdev')
for a, b in zip(near, far):
    print('%.9g %.9g' % (a, b))
)";

void ExpectEqualsMrcal(const fs::path& images, const std::string& target_flags,
                       const fs::path& dir) {
  const std::string portcal = testing::PortcalBinary();
  const std::string db = (dir / "db.db").string(), out = (dir / "cal").string();
  const testing::CommandResult extract = testing::RunCommand(
      portcal + " target_extractor --log_level warn --database_path " + db + " --image_path " +
      images.string() + " --ImageReader.camera_model OPENCV --ImageReader.single_camera 1 " +
      target_flags);
  ASSERT_EQ(extract.exit_code, 0) << extract.output;
  const testing::CommandResult calibrate =
      testing::RunCommand(portcal + " camera_calibrator --log_level warn --database_path " + db +
                          " --output_path " + out);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;
  ASSERT_TRUE(fs::exists(dir / "cal/camera.cameramodel"));

  const YAML::Node grid =
      YAML::LoadFile((dir / "cal/calibration.yaml").string())["projection_uncertainty"];
  ASSERT_TRUE(grid) << "calibration.yaml has no projection_uncertainty";
  ASSERT_TRUE(grid["determined"].as<bool>());
  EXPECT_EQ(grid["of"].as<std::string>(), "intrinsics");
  const auto xs = grid["x_px"].as<std::vector<double>>();
  const auto ys = grid["y_px"].as<std::vector<double>>();
  const double depth = grid["working_distance_m"].as<double>();
  std::ofstream pixels(dir / "pixels.txt");
  pixels.precision(17);
  for (double y : ys) {
    for (double x : xs) pixels << x << " " << y << "\n";
  }
  pixels.close();
  std::ofstream(dir / "script.py") << kMrcalScript;
  const testing::CommandResult mrcal =
      testing::RunCommand("/usr/bin/python3 " + (dir / "script.py").string() + " " +
                          (dir / "cal/camera.cameramodel").string() + " " + std::to_string(depth) +
                          " " + (dir / "pixels.txt").string() + " 2>&1");
  ASSERT_EQ(mrcal.exit_code, 0) << mrcal.output;
  std::istringstream lines(mrcal.output);
  double worst_ratio[2] = {1, 1}, sum[2][2] = {{0, 0}, {0, 0}};
  for (size_t r = 0; r < ys.size(); ++r) {
    const auto near = grid["at_working_distance_px"][r].as<std::vector<double>>();
    const auto far = grid["at_infinity_px"][r].as<std::vector<double>>();
    ASSERT_EQ(near.size(), xs.size());
    for (size_t c = 0; c < xs.size(); ++c) {
      double mrcal_near = 0, mrcal_far = 0;
      ASSERT_TRUE(lines >> mrcal_near >> mrcal_far) << mrcal.output;
      ASSERT_GT(near[c], 0) << "cell " << r << "," << c;
      const double ratios[2] = {near[c] / mrcal_near, far[c] / mrcal_far};
      for (int k = 0; k < 2; ++k) {
        EXPECT_NEAR(ratios[k], 1.0, 0.10)
            << "cell " << r << "," << c << (k ? " at infinity" : " at the distance") << ": portcal "
            << (k ? far[c] : near[c]) << " px, mrcal " << (k ? mrcal_far : mrcal_near) << " px";
        if (std::abs(ratios[k] - 1) > std::abs(worst_ratio[k] - 1)) worst_ratio[k] = ratios[k];
      }
      sum[0][0] += near[c], sum[0][1] += mrcal_near, sum[1][0] += far[c], sum[1][1] += mrcal_far;
    }
  }
  const double n = static_cast<double>(xs.size() * ys.size());
  std::printf(
      "projection uncertainty at %.3f m, mean over %zux%zu cells: portcal %.4f px, mrcal %.4f px "
      "(worst "
      "cell ratio %.3f); at infinity: portcal %.4f px, mrcal %.4f px (worst cell ratio %.3f)\n",
      depth, xs.size(), ys.size(), sum[0][0] / n, sum[0][1] / n, worst_ratio[0], sum[1][0] / n,
      sum[1][1] / n, worst_ratio[1]);
}

bool MrcalImports() {
  return testing::RunCommand("/usr/bin/python3 -c 'import mrcal' 2>&1").exit_code == 0;
}

TEST(MrcalUncertainty, RealInAirSetEqualsMrcal) {
  PORTCAL_REQUIRE_SHARED(shared);
  if (!MrcalImports())
    GTEST_SKIP() << "mrcal's Python module is not importable by /usr/bin/python3";
  const fs::path images = shared / "datasets/real-dome/air";
  if (!fs::exists(images)) GTEST_SKIP() << images << " is absent";
  testing::TempDir dir;
  ExpectEqualsMrcal(images, "--Target.cols 8 --Target.rows 6 --Target.square_size 0.03",
                    dir.path());
}

TEST(MrcalUncertainty, RenderedSetEqualsMrcal) {
  PORTCAL_REQUIRE_SHARED(shared);
  if (!MrcalImports())
    GTEST_SKIP() << "mrcal's Python module is not importable by /usr/bin/python3";
  const fs::path set = shared / "datasets/rendered/chess_air_distorted";
  if (!fs::exists(set / "images")) GTEST_SKIP() << set << " is absent";
  const YAML::Node target = YAML::LoadFile((set / "ground_truth.yaml").string())["target"];
  testing::TempDir dir;
  ExpectEqualsMrcal(set / "images",
                    "--Target.cols " + target["inner_corners_cols"].as<std::string>() +
                        " --Target.rows " + target["inner_corners_rows"].as<std::string>() +
                        " --Target.square_size " + target["square_size"].as<std::string>(),
                    dir.path());
}

}  // namespace
}  // namespace portcal
