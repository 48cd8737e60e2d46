// OPENCV, FULL_OPENCV and OPENCV_FISHEYE against OpenCV's own projection
// (cv::projectPoints, cv::fisheye::projectPoints). OpenCV puts the centre of
// the top-left pixel at (0, 0), COLMAP at (0.5, 0.5): with cx_colmap =
// cx_opencv + 0.5 the pixels differ by exactly 0.5.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include "colmap_ext/camera/camera_models.h"

namespace portcal {
namespace {

std::vector<cv::Point3d> TestPoints() {
  std::vector<cv::Point3d> points;
  for (double x = -0.6; x <= 0.6; x += 0.15) {
    for (double y = -0.45; y <= 0.45; y += 0.15) points.emplace_back(x, y, 1.3);
  }
  return points;
}

template <typename Model>
void ExpectSameAsOpenCV(const std::vector<double>& params,
                        const std::vector<cv::Point2d>& opencv_pixels,
                        const std::vector<cv::Point3d>& points) {
  ASSERT_EQ(opencv_pixels.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    double x, y;
    ASSERT_TRUE(Model::ImgFromCam(params.data(), points[i].x, points[i].y, points[i].z, &x, &y));
    EXPECT_NEAR(x - 0.5, opencv_pixels[i].x, 1e-9) << Model::kName << " point " << i;
    EXPECT_NEAR(y - 0.5, opencv_pixels[i].y, 1e-9) << Model::kName << " point " << i;
  }
}

cv::Mat CameraMatrix(double fx, double fy, double cx_opencv, double cy_opencv) {
  return (cv::Mat_<double>(3, 3) << fx, 0, cx_opencv, 0, fy, cy_opencv, 0, 0, 1);
}

TEST(CameraModelsVsOpenCV, OpenCVMatchesProjectPoints) {
  const std::vector<double> opencv = {-0.21, 0.06, 0.0012, -0.0017};
  const std::vector<double> params = {812,       796,       640.5,     360.5,
                                      opencv[0], opencv[1], opencv[2], opencv[3]};
  const std::vector<cv::Point3d> points = TestPoints();
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    CameraMatrix(812, 796, 640, 360), opencv, pixels);
  ExpectSameAsOpenCV<OpenCVModel>(params, pixels, points);
}

TEST(CameraModelsVsOpenCV, FullOpenCVMatchesProjectPointsRationalModel) {
  // OpenCV's order: k1 k2 p1 p2 k3 k4 k5 k6 = COLMAP's extra parameters.
  const std::vector<double> opencv = {-0.21, 0.06, 0.0012, -0.0017, 0.011, 0.021, 0.0031, 0.0012};
  std::vector<double> params = {812, 796, 640.5, 360.5};
  params.insert(params.end(), opencv.begin(), opencv.end());
  const std::vector<cv::Point3d> points = TestPoints();
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    CameraMatrix(812, 796, 640, 360), opencv, pixels);
  ExpectSameAsOpenCV<FullOpenCVModel>(params, pixels, points);
}

TEST(CameraModelsVsOpenCV, OpenCVFisheyeMatchesFisheyeProjectPoints) {
  const cv::Vec4d opencv(0.051, -0.012, 0.0021, -0.0006);
  const std::vector<double> params = {812,       796,       640.5,     360.5,
                                      opencv[0], opencv[1], opencv[2], opencv[3]};
  std::vector<cv::Point3d> points = TestPoints();
  points.emplace_back(2.0, 1.0, 0.7);  // 72 degrees off axis
  std::vector<cv::Point2d> pixels;
  cv::fisheye::projectPoints(points, pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                             cv::Matx33d(812, 0, 640, 0, 796, 360, 0, 0, 1), opencv);
  ExpectSameAsOpenCV<OpenCVFisheyeModel>(params, pixels, points);
}

// Undistortion agrees with cv::undistortPoints (iterative inside OpenCV, so
// compared at OpenCV's own tolerance with many iterations).
TEST(CameraModelsVsOpenCV, UnprojectMatchesUndistortPoints) {
  const std::vector<double> opencv = {-0.21, 0.06, 0.0012, -0.0017};
  const std::vector<double> params = {812,       796,       640.5,     360.5,
                                      opencv[0], opencv[1], opencv[2], opencv[3]};
  std::vector<cv::Point2d> pixels_opencv;
  for (double x = 100; x < 1200; x += 150) {
    for (double y = 80; y < 700; y += 120) pixels_opencv.emplace_back(x, y);
  }
  std::vector<cv::Point2d> normalized;
  cv::undistortPoints(
      pixels_opencv, normalized, CameraMatrix(812, 796, 640, 360), opencv, cv::noArray(),
      cv::noArray(), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-15));
  for (size_t i = 0; i < pixels_opencv.size(); ++i) {
    double u, v;
    ASSERT_TRUE(OpenCVModel::CamFromImg(params.data(), pixels_opencv[i].x + 0.5,
                                        pixels_opencv[i].y + 0.5, &u, &v));
    EXPECT_NEAR(u, normalized[i].x, 1e-9);
    EXPECT_NEAR(v, normalized[i].y, 1e-9);
  }
}

}  // namespace
}  // namespace portcal
