// Every COLMAP camera model gets the same checks: ids and names, round trips
// to 1e-9 px, and autodiff derivatives against central differences.
#include "colmap_ext/camera/camera_models.h"

#include <gtest/gtest.h>

#include <set>

#include "colmap_ext/camera/camera.h"

namespace portcal {
namespace {

// Realistic parameters: f ~ 800 px on a 1000 x 800 image, distortion of the
// size real lenses have.
template <typename Model>
std::vector<double> TestParams() {
  std::vector<double> p = Model::InitializeParams(800.0, 1000, 800);
  p[0] = 810.0;
  if (!Model::kSingleFocal) p[1] = 790.0;
  p[Model::FocalCount()] = 505.0;
  p[Model::FocalCount() + 1] = 396.0;
  const std::map<std::string, std::vector<double>> extra = {
      {"SIMPLE_RADIAL", {-0.1}},
      {"RADIAL", {-0.1, 0.02}},
      {"OPENCV", {-0.2, 0.05, 0.001, -0.0015}},
      {"OPENCV_FISHEYE", {0.05, -0.01, 0.002, -0.0005}},
      {"FULL_OPENCV", {-0.2, 0.05, 0.001, -0.0015, 0.01, 0.02, 0.003, 0.001}},
      {"FOV", {0.9}},
      {"SIMPLE_RADIAL_FISHEYE", {0.05}},
      {"RADIAL_FISHEYE", {0.05, -0.01}},
      {"THIN_PRISM_FISHEYE", {0.05, -0.01, 0.001, -0.001, 0.002, -0.0005, 0.0008, -0.0006}},
  };
  const auto it = extra.find(Model::kName);
  if (it != extra.end()) {
    for (size_t i = 0; i < it->second.size(); ++i) {
      p[Model::ExtraOffset() + i] = it->second[i];
    }
  }
  return p;
}

std::vector<Eigen::Vector2d> PixelGrid() {
  std::vector<Eigen::Vector2d> pixels;
  for (double x = 0.5; x < 1000; x += 47.5) {
    for (double y = 0.5; y < 800; y += 41.0) pixels.emplace_back(x, y);
  }
  return pixels;
}

template <typename Model>
class CameraModelTest : public ::testing::Test {};

using AllModels =
    ::testing::Types<SimplePinholeModel, PinholeModel, SimpleRadialModel, RadialModel, OpenCVModel,
                     OpenCVFisheyeModel, FullOpenCVModel, FOVModel, SimpleRadialFisheyeModel,
                     RadialFisheyeModel, ThinPrismFisheyeModel>;
TYPED_TEST_SUITE(CameraModelTest, AllModels);

TYPED_TEST(CameraModelTest, IndexSetsPartitionTheParameters) {
  using Model = TypeParam;
  std::set<int> all;
  for (int i : Model::FocalLengthIdxs()) EXPECT_TRUE(all.insert(i).second);
  for (int i : Model::PrincipalPointIdxs()) EXPECT_TRUE(all.insert(i).second);
  for (int i : Model::ExtraParamsIdxs()) EXPECT_TRUE(all.insert(i).second);
  EXPECT_EQ(static_cast<int>(all.size()), Model::kNumParams);
  EXPECT_EQ(CameraModelNumParams(Model::kId), Model::kNumParams);
  // kParamsInfo names exactly kNumParams parameters.
  const std::string info = Model::kParamsInfo;
  EXPECT_EQ(std::count(info.begin(), info.end(), ',') + 1, Model::kNumParams);
}

TYPED_TEST(CameraModelTest, UnprojectThenProjectReturnsThePixel) {
  using Model = TypeParam;
  const std::vector<double> params = TestParams<Model>();
  for (const Eigen::Vector2d& pixel : PixelGrid()) {
    double u, v;
    ASSERT_TRUE(Model::CamFromImg(params.data(), pixel.x(), pixel.y(), &u, &v))
        << Model::kName << " pixel " << pixel.transpose();
    for (const double depth : {0.3, 7.0}) {
      double x, y;
      ASSERT_TRUE(Model::ImgFromCam(params.data(), u * depth, v * depth, depth, &x, &y));
      EXPECT_NEAR(x, pixel.x(), 1e-9) << Model::kName;
      EXPECT_NEAR(y, pixel.y(), 1e-9) << Model::kName;
    }
  }
}

TYPED_TEST(CameraModelTest, ProjectThenUnprojectReturnsTheRay) {
  using Model = TypeParam;
  const std::vector<double> params = TestParams<Model>();
  for (double u = -0.5; u <= 0.5; u += 0.1) {
    for (double v = -0.4; v <= 0.4; v += 0.1) {
      double x, y, u2, v2;
      ASSERT_TRUE(Model::ImgFromCam(params.data(), u, v, 1.0, &x, &y));
      ASSERT_TRUE(Model::CamFromImg(params.data(), x, y, &u2, &v2));
      EXPECT_NEAR(u2, u, 1e-12) << Model::kName;
      EXPECT_NEAR(v2, v, 1e-12) << Model::kName;
    }
  }
}

TYPED_TEST(CameraModelTest, PointsBehindTheCameraDoNotProject) {
  using Model = TypeParam;
  const std::vector<double> params = TestParams<Model>();
  double x = -1, y = -1;
  EXPECT_FALSE(Model::ImgFromCam(params.data(), 0.1, 0.1, -1.0, &x, &y));
  EXPECT_FALSE(Model::ImgFromCam(params.data(), 0.1, 0.1, 0.0, &x, &y));
  EXPECT_EQ(x, -1);  // outputs untouched
}

// Jacobian of ImgFromCam w.r.t. (params, point) by autodiff against central
// differences; and of CamFromImg w.r.t. params (implicit function theorem).
TYPED_TEST(CameraModelTest, AutodiffMatchesCentralDifferences) {
  using Model = TypeParam;
  constexpr int N = Model::kNumParams;
  using Jet = ceres::Jet<double, N + 3>;
  const std::vector<double> params = TestParams<Model>();
  const Eigen::Vector3d point(0.21, -0.13, 1.7);
  const Eigen::Vector2d pixel(733.0, 187.0);

  Jet params_jet[N];
  for (int i = 0; i < N; ++i) params_jet[i] = Jet(params[i], i);
  Jet point_jet[3];
  for (int i = 0; i < 3; ++i) point_jet[i] = Jet(point[i], N + i);
  Jet x, y;
  ASSERT_TRUE(Model::ImgFromCam(params_jet, point_jet[0], point_jet[1], point_jet[2], &x, &y));
  Jet u, v;
  ASSERT_TRUE(Model::CamFromImg(params_jet, Jet(pixel.x()), Jet(pixel.y()), &u, &v));

  for (int k = 0; k < N + 3; ++k) {
    const double h = k < N ? 1e-6 * std::max(1.0, std::abs(params[k])) : 1e-7;
    std::vector<double> plus = params, minus = params;
    Eigen::Vector3d point_plus = point, point_minus = point;
    if (k < N) {
      plus[k] += h;
      minus[k] -= h;
    } else {
      point_plus[k - N] += h;
      point_minus[k - N] -= h;
    }
    double xp, yp, xm, ym;
    ASSERT_TRUE(
        Model::ImgFromCam(plus.data(), point_plus[0], point_plus[1], point_plus[2], &xp, &yp));
    ASSERT_TRUE(
        Model::ImgFromCam(minus.data(), point_minus[0], point_minus[1], point_minus[2], &xm, &ym));
    const double scale = 1e-6 * (1.0 + std::abs(x.v[k]) + std::abs(y.v[k]));
    EXPECT_NEAR(x.v[k], (xp - xm) / (2 * h), 1e-3 * scale + 1e-5) << Model::kName << " d/d" << k;
    EXPECT_NEAR(y.v[k], (yp - ym) / (2 * h), 1e-3 * scale + 1e-5) << Model::kName << " d/d" << k;
    if (k < N) {
      double up, vp, um, vm;
      ASSERT_TRUE(Model::CamFromImg(plus.data(), pixel.x(), pixel.y(), &up, &vp));
      ASSERT_TRUE(Model::CamFromImg(minus.data(), pixel.x(), pixel.y(), &um, &vm));
      EXPECT_NEAR(u.v[k], (up - um) / (2 * h), 1e-7) << Model::kName << " d/d" << k;
      EXPECT_NEAR(v.v[k], (vp - vm) / (2 * h), 1e-7) << Model::kName << " d/d" << k;
    }
  }
}

TEST(CameraModels, IdsAndNamesAreCOLMAPs) {
  const std::vector<std::string> expected = {"SIMPLE_PINHOLE",
                                             "PINHOLE",
                                             "SIMPLE_RADIAL",
                                             "RADIAL",
                                             "OPENCV",
                                             "OPENCV_FISHEYE",
                                             "FULL_OPENCV",
                                             "FOV",
                                             "SIMPLE_RADIAL_FISHEYE",
                                             "RADIAL_FISHEYE",
                                             "THIN_PRISM_FISHEYE"};
  std::vector<std::string> names;
  std::set<int> ids;
  ForEachModel(CameraModelList{}, [&](auto model) {
    using Model = decltype(model);
    EXPECT_EQ(Model::kId, static_cast<int>(names.size()));
    EXPECT_TRUE(ids.insert(Model::kId).second);
    names.push_back(Model::kName);
  });
  EXPECT_EQ(names, expected);
  const std::vector<int> num_params = {3, 4, 4, 5, 8, 8, 12, 5, 4, 5, 12};
  for (int id = 0; id < kNumCameraModels; ++id) {
    EXPECT_EQ(CameraModelNameToId(expected[id]), id);
    EXPECT_EQ(CameraModelIdToName(id), expected[id]);
    EXPECT_EQ(CameraModelNumParams(id), num_params[id]);
    // The fisheye models are those on the equidistant angle (COLMAP's ids
    // 5, 8, 9, 10), by their names.
    EXPECT_EQ(CameraModelIsFisheye(id), expected[id].find("FISHEYE") != std::string::npos)
        << expected[id];
  }
}

TEST(CameraModels, UnknownNamesAndIdsAreClearErrors) {
  try {
    CameraModelNameToId("OPENCV5");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("OPENCV5"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("THIN_PRISM_FISHEYE"), std::string::npos);
  }
  EXPECT_THROW(CameraModelIdToName(11), InputError);
  EXPECT_FALSE(ExistsCameraModelWithId(-1));
}

TEST(Camera, ValidateNamesTheProblem) {
  Camera camera = Camera::FromModelName("OPENCV", 1000, 640, 480);
  EXPECT_NO_THROW(camera.Validate("cam"));
  camera.params.pop_back();
  try {
    camera.Validate("cameras.txt:4");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.txt:4"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("8 parameters"), std::string::npos);
  }
  camera = Camera::FromModelName("PINHOLE", 1000, 640, 480);
  camera.params[1] = std::nan("");
  EXPECT_THROW(camera.Validate("x"), InputError);
  camera.params[1] = -5;
  EXPECT_THROW(camera.Validate("x"), InputError);
}

TEST(Camera, DefaultParamsFollowCOLMAP) {
  const Camera camera = Camera::FromModelName("FOV", 1200, 640, 480);
  EXPECT_EQ(camera.params, (std::vector<double>{1200, 1200, 320, 240, 1e-2}));
  const Camera simple = Camera::FromModelName("SIMPLE_RADIAL", 1200, 640, 480);
  EXPECT_EQ(simple.params, (std::vector<double>{1200, 320, 240, 0}));
}

// The FOV model's series branches join the closed form continuously.
TEST(CameraModels, FovSeriesBranchesAreContinuous) {
  const double omegas[] = {1e-5, 0.5};
  for (const double omega : omegas) {
    const double params[5] = {800, 800, 400, 300, omega};
    for (const double r : {1e-6, 2e-5, 0.3}) {
      double x, y;
      ASSERT_TRUE(FOVModel::ImgFromCam(params, r, 0.0, 1.0, &x, &y));
      const double a = 2 * std::tan(omega / 2);
      const double expected = 800 * std::atan(r * a) / omega + 400;
      EXPECT_NEAR(x, expected, 1e-9) << "omega " << omega << " r " << r;
    }
  }
}

}  // namespace
}  // namespace portcal
