#include "colmap_ext/io/opencv_camera_file.h"

#include <iomanip>
#include <ostream>
#include <vector>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

// The camera in OpenCV's terms.
struct OpenCvCamera {
  double fx, fy, cx, cy;
  std::vector<double> distortion;
  std::string ros_model;  // plumb_bob | rational_polynomial | equidistant
  bool fisheye = false;
};

OpenCvCamera ToOpenCv(const Camera& camera) {
  const std::string model = camera.ModelName();
  const std::vector<double>& p = camera.params;
  OpenCvCamera out;
  out.cx = camera.PrincipalPointX() - 0.5;
  out.cy = camera.PrincipalPointY() - 0.5;
  out.ros_model = "plumb_bob";
  if (model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL") {
    out.fx = out.fy = p[0];
    out.distortion = {0, 0, 0, 0, 0};
    if (model != "SIMPLE_PINHOLE") out.distortion[0] = p[3];
    if (model == "RADIAL") out.distortion[1] = p[4];
  } else if (model == "PINHOLE" || model == "OPENCV" || model == "FULL_OPENCV" ||
             model == "OPENCV_FISHEYE") {
    out.fx = p[0];
    out.fy = p[1];
    if (model == "PINHOLE") {
      out.distortion = {0, 0, 0, 0, 0};
    } else if (model == "OPENCV") {
      out.distortion = {p[4], p[5], p[6], p[7], 0};
    } else if (model == "FULL_OPENCV") {
      out.distortion.assign(p.begin() + 4, p.end());  // k1 k2 p1 p2 k3 k4 k5 k6
      out.ros_model = "rational_polynomial";
    } else {
      out.distortion.assign(p.begin() + 4, p.end());  // k1..k4 of cv::fisheye
      out.ros_model = "equidistant";
      out.fisheye = true;
    }
  } else {
    throw InputError("camera model " + model + " cannot be written for OpenCV/ROS; nearest: " +
                     (model == "FOV" ? std::string("FULL_OPENCV")
                                     : std::string("OPENCV_FISHEYE")) +
                     " (re-calibrate with it)");
  }
  return out;
}

void WriteList(std::ostream& out, const std::vector<double>& values) {
  out << "[";
  for (size_t i = 0; i < values.size(); ++i) out << (i ? ", " : " ") << values[i];
  out << " ]";
}

std::vector<double> CameraMatrix(const OpenCvCamera& c) {
  return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
}

}  // namespace

void WriteOpenCvCameraYaml(const Camera& camera, const std::filesystem::path& path) {
  const OpenCvCamera c = ToOpenCv(camera);
  WriteFileAtomically(path, false, [&](std::ostream& out) {
    out << std::setprecision(17);
    out << "%YAML:1.0\n---\n";
    out << "image_width: " << camera.width << "\nimage_height: " << camera.height << "\n";
    out << "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: ";
    WriteList(out, CameraMatrix(c));
    out << "\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: "
        << c.distortion.size() << "\n   dt: d\n   data: ";
    WriteList(out, c.distortion);
    out << "\n";
    // Which OpenCV functions the coefficients are for: cv::fisheye:: or the
    // standard (cv::undistort, cv::projectPoints).
    out << "distortion_model: \"" << (c.fisheye ? "fisheye" : "standard") << "\"\n";
  });
}

void WriteRosCameraInfoYaml(const Camera& camera, const std::string& camera_name,
                            const std::filesystem::path& path) {
  const OpenCvCamera c = ToOpenCv(camera);
  WriteFileAtomically(path, false, [&](std::ostream& out) {
    out << std::setprecision(17);
    out << "image_width: " << camera.width << "\nimage_height: " << camera.height << "\n";
    out << "camera_name: " << camera_name << "\n";
    out << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: ";
    WriteList(out, CameraMatrix(c));
    out << "\ndistortion_model: " << c.ros_model << "\n";
    out << "distortion_coefficients:\n  rows: 1\n  cols: " << c.distortion.size() << "\n  data: ";
    WriteList(out, c.distortion);
    out << "\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: ";
    WriteList(out, {1, 0, 0, 0, 1, 0, 0, 0, 1});
    // Monocular: P = [K | 0] (no rectification, the distorted camera's K).
    out << "\nprojection_matrix:\n  rows: 3\n  cols: 4\n  data: ";
    WriteList(out, {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0});
    out << "\n";
  });
}

}  // namespace portcal
