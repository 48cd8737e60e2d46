#include "colmap_ext/io/opencv_camera_file.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <vector>

#include "colmap_ext/camera/camera_models.h"
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
                     (model == "FOV" ? std::string("FULL_OPENCV") : std::string("OPENCV_FISHEYE")) +
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

namespace {

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// OpenCV's FileStorage writes a YAML 1.0 directive ("%YAML:1.0") that YAML
// 1.2 parsers reject; its "!!opencv-matrix" tags are plain tags.
YAML::Node LoadOpenCvYaml(const std::filesystem::path& path) {
  std::string text = ReadText(path);
  if (text.rfind("%YAML:1.0", 0) == 0) text.erase(0, text.find('\n'));
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

std::vector<double> MatrixData(const YAML::Node& root, const std::string& key,
                               const std::filesystem::path& path) {
  if (!root[key] || !root[key]["data"])
    throw InputError(path.string() + ": no '" + key + "' with 'data'");
  try {
    return root[key]["data"].as<std::vector<double>>();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": '" + key + "': " + e.what());
  }
}

uint64_t ImageSize(const YAML::Node& root, const std::string& key,
                   const std::filesystem::path& path) {
  try {
    if (root[key]) return root[key].as<uint64_t>();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": '" + key + "': " + e.what());
  }
  throw InputError(path.string() + ": no '" + key + "' (the image size the calibration is for)");
}

// The COLMAP camera of OpenCV's coefficients (see ReadOpenCvCameraYaml).
Camera CameraOfOpenCv(double fx, double fy, double cx, double cy, const std::vector<double>& d,
                      bool fisheye, uint64_t width, uint64_t height,
                      const std::filesystem::path& path) {
  // COLMAP puts the centre of the top-left pixel at (0.5, 0.5), OpenCV at 0.
  std::vector<double> params = {fx, fy, cx + 0.5, cy + 0.5};
  std::string model;
  const auto all_zero = [&](size_t from) {
    return std::all_of(d.begin() + static_cast<std::ptrdiff_t>(std::min(from, d.size())), d.end(),
                       [](double v) { return v == 0; });
  };
  if (fisheye) {
    if (d.size() != 4)
      throw InputError(path.string() + ": a fisheye camera needs 4 distortion coefficients");
    model = "OPENCV_FISHEYE";
    params.insert(params.end(), d.begin(), d.end());
  } else if (all_zero(0)) {
    model = "PINHOLE";
  } else if (d.size() >= 4 && all_zero(4)) {
    model = "OPENCV";
    params.insert(params.end(), d.begin(), d.begin() + 4);
  } else if (d.size() == 5 || d.size() == 8) {
    model = "FULL_OPENCV";
    std::vector<double> k(8, 0.0);
    std::copy(d.begin(), d.end(), k.begin());
    params.insert(params.end(), k.begin(), k.end());
  } else {
    throw InputError(path.string() + ": " + std::to_string(d.size()) +
                     " distortion coefficients; portcal reads 4 (fisheye), 5 (plumb_bob) or 8 "
                     "(rational_polynomial)");
  }
  Camera camera;
  camera.model_id = CameraModelNameToId(model);
  camera.width = width;
  camera.height = height;
  camera.params = params;
  camera.Validate(path.string());
  return camera;
}

}  // namespace

bool IsOpenCvOrRosCameraYaml(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::string first;
  if (!file || !std::getline(file, first)) return false;
  if (first.rfind("%YAML:1.0", 0) == 0) return true;
  file.seekg(0);
  for (std::string line; std::getline(file, line);) {
    if (line.rfind("camera_matrix:", 0) == 0) return true;
  }
  return false;
}

namespace {

// The body of ReadOpenCvCameraYaml; yaml-cpp's exceptions (a key looked up in a scalar, a
// value of the wrong type) are turned into InputError by the caller.
Camera ReadOpenCvCameraYamlUnguarded(const std::filesystem::path& path) {
  const YAML::Node root = LoadOpenCvYaml(path);
  const std::vector<double> k = MatrixData(root, "camera_matrix", path);
  if (k.size() != 9) throw InputError(path.string() + ": 'camera_matrix' needs 9 values");
  const std::vector<double> d = root["distortion_coefficients"]
                                    ? MatrixData(root, "distortion_coefficients", path)
                                    : std::vector<double>();
  std::string distortion_model;
  if (root["distortion_model"]) distortion_model = root["distortion_model"].as<std::string>();
  const bool fisheye = distortion_model == "fisheye" || distortion_model == "equidistant";
  if (!fisheye && !distortion_model.empty() && distortion_model != "standard" &&
      distortion_model != "plumb_bob" && distortion_model != "rational_polynomial") {
    throw InputError(
        path.string() + ": distortion_model '" + distortion_model +
        "'; portcal reads plumb_bob, rational_polynomial, equidistant (ROS) or standard, fisheye "
        "(OpenCV)");
  }
  if (k[1] != 0)
    throw InputError(path.string() + ": a skewed camera_matrix (COLMAP's models have no skew)");
  return CameraOfOpenCv(k[0], k[4], k[2], k[5], d, fisheye, ImageSize(root, "image_width", path),
                        ImageSize(root, "image_height", path), path);
}

}  // namespace

Camera ReadOpenCvCameraYaml(const std::filesystem::path& path) {
  try {
    return ReadOpenCvCameraYamlUnguarded(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

}  // namespace portcal
