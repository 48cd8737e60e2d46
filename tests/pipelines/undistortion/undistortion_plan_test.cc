// How image_undistorter plans each camera: the depths of a model's points
// (5th-95th percentile, none below 10 points), the design depth and range
// from the options, and errors that name the option when no depth is known
// behind a port or the nearest lies inside the housing.
#include "pipelines/undistortion/undistortion_plan.h"

#include <gtest/gtest.h>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

Camera Lens() {
  Camera camera = Camera::FromModelName("RADIAL", 1, 320, 240);
  camera.camera_id = 1;
  camera.params = {300, 160, 120, -0.05, 0.01};
  return camera;
}

Housing FlatPort() {
  return Housing::FromName("FLATPORT", {0, 0, 1, 0.02, 0.01, 1.0, 1.49, 1.334}, "test");
}

// Camera 1 at the origin looking along z at points at depths 1..n (m).
SparseModel ModelWithDepths(int n) {
  SparseModel model;
  model.cameras[1] = Lens();
  Image image;
  image.image_id = 1;
  image.camera_id = 1;
  for (int k = 1; k <= n; ++k) {
    model.points3D[k].xyz = Eigen::Vector3d(0.01 * k, 0, k);
    Point2D point;
    point.point3D_id = k;
    image.points2D.push_back(point);
  }
  model.images[1] = image;
  return model;
}

TEST(UndistortionPlan, PointDepthsAreTheMiddleNinetyPercent) {
  EXPECT_FALSE(PointDepthRange(ModelWithDepths(9), 1));  // too few to say
  const std::optional<DepthRange> range = PointDepthRange(ModelWithDepths(101), 1);
  ASSERT_TRUE(range);
  EXPECT_DOUBLE_EQ(range->near, 6.0);                      // the 5th percentile of 1..101
  EXPECT_DOUBLE_EQ(range->far, 96.0);                      // the 95th
  EXPECT_FALSE(PointDepthRange(ModelWithDepths(101), 2));  // another camera's
}

TEST(UndistortionPlan, DepthsComeFromTheOptionsBeforeThePoints) {
  const HousedCamera camera{Lens(), FlatPort()};
  UndistortionPlanOptions options;
  options.num_threads = 1;
  options.distance = 2.0;
  const CameraUndistortion by_distance =
      PlanCamera(options, camera, DepthRange{5, 9}, Eigen::Matrix3d::Identity());
  EXPECT_DOUBLE_EQ(by_distance.pinhole.design_depth, 2.0);
  EXPECT_DOUBLE_EQ(by_distance.range.near, 1.0);  // half to twice the distance
  EXPECT_DOUBLE_EQ(by_distance.range.far, 4.0);
  EXPECT_GE(by_distance.error.depths.size(), 5u);  // --Undistort.num_error_depths

  options.distance = 0;
  const CameraUndistortion by_points =
      PlanCamera(options, camera, DepthRange{1.5, 3.0}, Eigen::Matrix3d::Identity());
  EXPECT_DOUBLE_EQ(by_points.range.near, 1.5);
  EXPECT_DOUBLE_EQ(by_points.range.far, 3.0);
  EXPECT_GE(by_points.pinhole.design_depth, 1.5);
  EXPECT_LE(by_points.pinhole.design_depth, 3.0);
}

TEST(UndistortionPlan, UnknownOrImpossibleDepthsBehindAPortNameTheOption) {
  const HousedCamera camera{Lens(), FlatPort()};
  UndistortionPlanOptions options;
  options.num_threads = 1;
  try {
    PlanCamera(options, camera, std::nullopt, Eigen::Matrix3d::Identity());
    ADD_FAILURE() << "no depth behind a port was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--Undistort.distance"), std::string::npos) << e.what();
  }
  options.distance = 0.01;  // inside the port, which reaches z = 0.03 m
  try {
    PlanCamera(options, camera, std::nullopt, Eigen::Matrix3d::Identity());
    ADD_FAILURE() << "a distance inside the housing was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inside camera 1's housing"), std::string::npos)
        << e.what();
  }
  // In air every depth maps alike: no depth is needed.
  options.distance = 0;
  const CameraUndistortion in_air =
      PlanCamera(options, {Lens(), std::nullopt}, std::nullopt, Eigen::Matrix3d::Identity());
  EXPECT_LT(in_air.error.worst_px, 1e-6);
}

TEST(UndistortionPlan, OptionsOutsideTheirRangeNameTheFlag) {
  UndistortionPlanOptions options;
  options.depth_range = {2.0, 1.0};
  EXPECT_THROW(options.Check(), OptionError);
  options.depth_range = {};
  options.num_error_depths = 1;
  try {
    options.Check();
    ADD_FAILURE();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--Undistort.num_error_depths = 1"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace portcal
