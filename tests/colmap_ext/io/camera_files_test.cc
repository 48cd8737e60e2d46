// Cameras in other tools' files: mrcal's .cameramodel (written by portcal,
// read by mrcal's own parser, projected by mrcal's own code), OpenCV's YAML
// (read by cv::FileStorage, projected by cv::projectPoints) and ROS
// camera_info. The pixel conventions differ by 0.5 px; every test projects.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>
#include <random>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/npz_archive.h"
#include "colmap_ext/io/opencv_camera_file.h"
#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace portcal {
namespace {

Camera MakeCamera(const std::string& model, std::vector<double> params) {
  Camera camera = Camera::FromModelName(model, 1000, 1600, 1200);
  camera.params = std::move(params);
  return camera;
}

std::vector<Camera> Cameras() {
  return {MakeCamera("SIMPLE_PINHOLE", {1210, 801.3, 598.2}),
          MakeCamera("PINHOLE", {1210, 1215, 801.3, 598.2}),
          MakeCamera("SIMPLE_RADIAL", {1210, 801.3, 598.2, -0.12}),
          MakeCamera("RADIAL", {1210, 801.3, 598.2, -0.12, 0.03}),
          MakeCamera("OPENCV", {1210, 1215, 801.3, 598.2, -0.12, 0.03, 0.001, -0.0007}),
          MakeCamera("FULL_OPENCV", {1210, 1215, 801.3, 598.2, -0.12, 0.03, 0.001, -0.0007, 0.004,
                                     0.01, -0.002, 0.0005})};
}

// Points spread over the field of view, in front of the camera.
std::vector<Eigen::Vector3d> Points() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i)
    points.emplace_back(u(rng), 0.75 * u(rng), 1.0 + 0.5 * (u(rng) + 0.6));
  return points;
}

TEST(MrcalModel, MrcalProjectsExactlyLikePortcalMinusHalfAPixel) {
  for (const Camera& camera : Cameras()) {
    const MrcalLens lens = MrcalLensFromCamera(camera);
    mrcal_lensmodel_t lensmodel;
    ASSERT_TRUE(mrcal_lensmodel_from_name(&lensmodel, lens.lensmodel.c_str()));
    for (const Eigen::Vector3d& p : Points()) {
      mrcal_point3_t point = {{p.x(), p.y(), p.z()}};
      mrcal_point2_t q;
      ASSERT_TRUE(
          mrcal_project(&q, nullptr, nullptr, &point, 1, &lensmodel, lens.intrinsics.data()));
      const Eigen::Vector2d ours = *camera.ImgFromCam(p);
      EXPECT_NEAR(q.x, ours.x() - 0.5, 1e-9) << camera.ModelName();
      EXPECT_NEAR(q.y, ours.y() - 0.5, 1e-9) << camera.ModelName();
    }
  }
}

TEST(MrcalModel, CameraModelFileRoundTripsThroughMrcalsParser) {
  testing::TempDir dir;
  for (const Camera& camera : Cameras()) {
    const Rigid3d cam_from_ref(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
        Eigen::Vector3d(0.1, -0.2, 0.05));
    const auto path = dir / (camera.ModelName() + ".cameramodel");
    WriteMrcalCameraModel(camera, cam_from_ref, path);
    const MrcalCameraModelFile read = ReadMrcalCameraModel(path);
    EXPECT_EQ(read.camera.width, camera.width);
    EXPECT_EQ(read.camera.height, camera.height);
    // Full precision: the same projection to 1e-9 px (the model may be the
    // wider one: RADIAL comes back as OPENCV).
    for (const Eigen::Vector3d& p : Points()) {
      EXPECT_LT((*read.camera.ImgFromCam(p) - *camera.ImgFromCam(p)).norm(), 1e-9)
          << camera.ModelName();
    }
    EXPECT_LT(read.cam_from_ref.rotation.angularDistance(cam_from_ref.rotation), 1e-12);
    EXPECT_LT((read.cam_from_ref.translation - cam_from_ref.translation).norm(), 1e-12);
  }
}

// A file mrcal itself wrote (its writer, its layout) imports exactly.
TEST(MrcalModel, ImportsWhatMrcalsPythonWrites) {
  if (testing::RunCommand("/usr/bin/python3 -c 'import mrcal' 2>&1").exit_code != 0) {
    GTEST_SKIP() << "mrcal's Python module is not importable by /usr/bin/python3";
  }
  testing::TempDir dir;
  const std::string path = (dir / "mrcal.cameramodel").string();
  const auto run = testing::RunCommand(
      "/usr/bin/python3 -c \"import mrcal, numpy as np; mrcal.cameramodel(intrinsics=("
      "'LENSMODEL_OPENCV8', np.array([1210., 1215., 800.8, 597.7, -0.12, 0.03, 0.001, -0.0007, "
      "0.004, 0.01, -0.002, 0.0005])), imagersize=(1600, 1200), extrinsics_rt_toref=np.array([0.1, "
      "0.2, "
      "0.3, 1., 2., 3.])).write('" +
      path + "')\" 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const MrcalCameraModelFile read = ReadMrcalCameraModel(path);
  EXPECT_EQ(read.camera.ModelName(), "FULL_OPENCV");
  const Camera expected = Cameras()[5];  // the same lens in COLMAP's convention
  // mrcal's writer keeps 6 decimals.
  for (size_t i = 0; i < expected.params.size(); ++i) {
    EXPECT_NEAR(read.camera.params[i], expected.params[i], 1e-6) << i;
  }
  // rt_cam_ref (what the file stores) is the inverse of the rt_toref given.
  const Rigid3d ref_from_cam = read.cam_from_ref.Inverse();
  EXPECT_NEAR(ref_from_cam.translation.x(), 1.0, 1e-6);
  EXPECT_NEAR(ref_from_cam.translation.z(), 3.0, 1e-6);
}

TEST(MrcalModel, ModelsWithoutCounterpartNameTheNearest) {
  const Camera fisheye = Camera::FromModelName("OPENCV_FISHEYE", 500, 640, 480);
  try {
    MrcalLensFromCamera(fisheye);
    FAIL() << "OPENCV_FISHEYE has no mrcal 2.2 counterpart";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nearest"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("OPENCV_FISHEYE"), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      CameraFromMrcalLens({"LENSMODEL_CAHVOR", std::vector<double>(9, 1.0)}, 640, 480, "x"),
      InputError);
  testing::TempDir dir;
  {
    std::ofstream out(dir / "bad.cameramodel");
    out << "{ 'lensmodel': 'LENSMODEL_OPENCV4', 'intrinsics': [1, 2] }\n";
  }
  EXPECT_THROW(ReadMrcalCameraModel(dir / "bad.cameramodel"), InputError);
}

TEST(OpenCvCameraFile, OpenCvReadsTheYamlAndProjectsLikePortcal) {
  testing::TempDir dir;
  std::vector<Camera> cameras = Cameras();
  cameras.push_back(
      MakeCamera("OPENCV_FISHEYE", {610, 612, 801.3, 598.2, 0.05, -0.01, 0.002, -0.0005}));
  for (const Camera& camera : cameras) {
    const auto path = dir / (camera.ModelName() + ".yaml");
    WriteOpenCvCameraYaml(camera, path);
    cv::FileStorage fs(path.string(), cv::FileStorage::READ);
    ASSERT_TRUE(fs.isOpened());
    const cv::Mat k = fs["camera_matrix"].mat();
    const cv::Mat d = fs["distortion_coefficients"].mat();
    EXPECT_EQ(static_cast<int>(fs["image_width"]), 1600);
    const bool fisheye = fs["distortion_model"].string() == "fisheye";
    EXPECT_EQ(fisheye, camera.ModelName() == "OPENCV_FISHEYE");
    std::vector<cv::Point3d> object;
    for (const Eigen::Vector3d& p : Points()) object.emplace_back(p.x(), p.y(), p.z());
    std::vector<cv::Point2d> projected;
    const cv::Mat zero = cv::Mat::zeros(3, 1, CV_64F);
    if (fisheye) {
      cv::fisheye::projectPoints(object, projected, zero, zero, k, d);
    } else {
      cv::projectPoints(object, zero, zero, k, d, projected);
    }
    for (size_t i = 0; i < object.size(); ++i) {
      const Eigen::Vector2d ours = *camera.ImgFromCam(Points()[i]);
      EXPECT_NEAR(projected[i].x, ours.x() - 0.5, 1e-7) << camera.ModelName();
      EXPECT_NEAR(projected[i].y, ours.y() - 0.5, 1e-7) << camera.ModelName();
    }
  }
  EXPECT_THROW(WriteOpenCvCameraYaml(Camera::FromModelName("FOV", 500, 640, 480), dir / "fov.yaml"),
               InputError);
}

TEST(OpenCvCameraFile, RosCameraInfoHasTheKeysCameraInfoManagerReads) {
  testing::TempDir dir;
  const Camera camera = Cameras()[4];  // OPENCV
  WriteRosCameraInfoYaml(camera, "left", dir / "left.yaml");
  const YAML::Node root = YAML::LoadFile((dir / "left.yaml").string());
  EXPECT_EQ(root["image_width"].as<int>(), 1600);
  EXPECT_EQ(root["camera_name"].as<std::string>(), "left");
  EXPECT_EQ(root["distortion_model"].as<std::string>(), "plumb_bob");
  const auto k = root["camera_matrix"]["data"].as<std::vector<double>>();
  ASSERT_EQ(k.size(), 9u);
  EXPECT_DOUBLE_EQ(k[2], camera.params[2] - 0.5);
  const auto d = root["distortion_coefficients"]["data"].as<std::vector<double>>();
  ASSERT_EQ(d.size(), 5u);
  EXPECT_DOUBLE_EQ(d[3], camera.params[7]);
  EXPECT_EQ(root["projection_matrix"]["data"].as<std::vector<double>>().size(), 12u);
  EXPECT_EQ(root["rectification_matrix"]["data"].as<std::vector<double>>().size(), 9u);
}

}  // namespace
}  // namespace portcal

namespace portcal {
namespace {

// Python's base64.b85encode, on groups short and whole (values from Python).
TEST(NpzArchive, Base85IsPythons) {
  EXPECT_EQ(EncodeBase85(""), "");
  EXPECT_EQ(EncodeBase85("h"), "Xa");
  EXPECT_EQ(EncodeBase85("hello"), "Xk~0{Zv");
  EXPECT_EQ(EncodeBase85(std::string(4, '\0')), "00000");
  EXPECT_EQ(EncodeBase85("\xff\xfe\xfd\xfc\xfb\xfa"), "|Ni~_`}z");
}

// NumPy reads the archive back: shapes, types, values, strings and None.
TEST(NpzArchive, NumpyReadsTheArchive) {
  if (testing::RunCommand("/usr/bin/python3 -c 'import numpy' 2>&1").exit_code != 0) {
    GTEST_SKIP() << "numpy is not importable by /usr/bin/python3";
  }
  NpzArchive npz;
  npz.AddDoubles("m", {2, 3}, {1, 2, 3, 4, 5, 6.5});
  npz.AddInt32s("i", {0, 6}, {});
  npz.AddBool("b", true);
  npz.AddDouble("d", 0.03);
  npz.AddString("none", "");
  npz.AddStrings("names", {"a.png", "image_10.png"});
  testing::TempDir dir;
  {
    std::ofstream out(dir / "a.npz", std::ios::binary);
    const std::string bytes = npz.Bytes();
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const auto run = testing::RunCommand(
      "/usr/bin/python3 -c \"import numpy as np; z = np.load('" + (dir / "a.npz").string() +
      "', allow_pickle=False); print(z['m'].shape, z['m'][1, 2], z['i'].shape, z['i'].dtype, "
      "z['b'].item(), "
      "z['d'].item(), repr(z['none'].item()), list(z['names']))\" 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output, "(2, 3) 6.5 (0, 6) int32 True 0.03 '' ['a.png', 'image_10.png']\n");
}

}  // namespace
}  // namespace portcal
