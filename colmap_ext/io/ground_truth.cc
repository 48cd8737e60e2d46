#include "colmap_ext/io/ground_truth.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// --- reading ---------------------------------------------------------------

class Reader {
 public:
  explicit Reader(const fs::path& path) : path_(path.string()) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw InputError(path_ + ": " + key + ": " + what);
  }

  template <typename T>
  T Get(const YAML::Node& node, const std::string& key) const {
    if (!node[key]) Fail(key, "missing");
    try {
      return node[key].as<T>();
    } catch (const YAML::Exception& e) {
      Fail(key, e.what());
    }
  }

  double Finite(const YAML::Node& node, const std::string& key) const {
    const double value = Get<double>(node, key);
    if (!std::isfinite(value)) Fail(key, "not finite");
    return value;
  }

  std::vector<double> Vector(const YAML::Node& node, const std::string& key, size_t size) const {
    const std::vector<double> values = Get<std::vector<double>>(node, key);
    if (size > 0 && values.size() != size) {
      Fail(key, "expected " + std::to_string(size) + " numbers");
    }
    for (double v : values) {
      if (!std::isfinite(v)) Fail(key, "not finite");
    }
    return values;
  }

  Eigen::Vector3d Point3(const YAML::Node& node, const std::string& what) const {
    std::vector<double> v;
    try {
      v = node.as<std::vector<double>>();
    } catch (const YAML::Exception& e) {
      Fail(what, e.what());
    }
    if (v.size() != 3) Fail(what, "expected 3 numbers");
    return {v[0], v[1], v[2]};
  }

  Rigid3d Pose(const YAML::Node& node, const std::string& key) const {
    if (!node[key]) Fail(key, "missing");
    const std::vector<double> q = Vector(node[key], "rotation_wxyz", 4);
    const std::vector<double> t = Vector(node[key], "translation", 3);
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    if (std::abs(rotation.norm() - 1.0) > 1e-6) Fail(key, "rotation is not a unit quaternion");
    return Rigid3d(rotation.normalized(), Eigen::Vector3d(t[0], t[1], t[2]));
  }

  Camera ReadCamera(const YAML::Node& node, const std::string& key) const {
    if (!node[key] || node[key].IsNull()) Fail(key, "missing");
    const YAML::Node c = node[key];
    Camera camera;
    try {
      camera.model_id = CameraModelNameToId(Get<std::string>(c, "model"));
    } catch (const InputError& e) {
      Fail(key, e.what());
    }
    camera.width = Get<int>(c, "width");
    camera.height = Get<int>(c, "height");
    camera.params = Vector(c, "params", 0);
    camera.Validate(path_ + ": " + key);
    return camera;
  }

  std::optional<Housing> ReadHousing(const YAML::Node& node, const std::string& key) const {
    if (!node[key] || node[key].IsNull()) return std::nullopt;
    return Housing::FromName(Get<std::string>(node[key], "model"), Vector(node[key], "params", 0),
                             path_ + ": " + key);
  }

  ImageTruth ReadImage(const YAML::Node& node, const std::string& where) const {
    ImageTruth image;
    image.file = Get<std::string>(node, "file");
    image.cam_from_target = Pose(node, "cam_from_target");
    if (node["corners_px"]) {
      for (const YAML::Node& c : node["corners_px"]) {
        if (c.IsNull()) {
          image.corners_px.emplace_back(std::nullopt);
          continue;
        }
        const auto v = c.as<std::vector<double>>();
        if (v.size() != 2) Fail(where + " corners_px", "expected pairs");
        image.corners_px.emplace_back(Eigen::Vector2d(v[0], v[1]));
      }
    }
    if (node["corners_visible"]) {
      for (const YAML::Node& c : node["corners_visible"])
        image.corners_visible.push_back(c.as<bool>());
    }
    if (node["markers"]) {
      for (const YAML::Node& m : node["markers"]) {
        ImageTruth::Marker marker;
        marker.id = Get<int>(m, "id");
        int k = 0;
        for (const YAML::Node& c : m["corners_px"]) {
          if (k >= 4) Fail(where + " markers", "more than 4 corners");
          const auto v = c.as<std::vector<double>>();
          if (v.size() != 2) Fail(where + " markers", "expected corners of 2 numbers");
          marker.corners_px[k++] = {v[0], v[1]};
        }
        if (k != 4) Fail(where + " markers", "expected 4 corners");
        marker.fully_inside = m["fully_inside"] ? m["fully_inside"].as<bool>() : true;
        image.markers.push_back(marker);
      }
    }
    return image;
  }

  TargetDescription ReadTarget(const YAML::Node& node) const {
    TargetDescription target;
    target.type = Get<std::string>(node, "type");
    const auto optional_int = [&](const char* key, int* out) {
      if (node[key]) *out = Get<int>(node, key);
    };
    const auto optional_double = [&](const char* key, double* out) {
      if (node[key]) *out = Finite(node, key);
    };
    optional_int("inner_corners_cols", &target.inner_corners_cols);
    optional_int("inner_corners_rows", &target.inner_corners_rows);
    optional_int("markers_x", &target.markers_x);
    optional_int("markers_y", &target.markers_y);
    optional_double("square_size", &target.square_size);
    optional_double("margin", &target.margin);
    optional_double("marker_size", &target.marker_size);
    optional_double("marker_separation", &target.marker_separation);
    optional_double("fold_angle_deg", &target.fold_angle_deg);
    optional_double("face_width", &target.face_width);
    optional_double("face_height", &target.face_height);
    if (node["aruco_dict"]) target.aruco_dictionary = Get<std::string>(node, "aruco_dict");
    if (node["layout"]) target.layout = Get<std::string>(node, "layout");
    if (node["dots_file"]) target.dots_file = Get<std::string>(node, "dots_file");
    if (node["corners_3d"]) {
      for (const YAML::Node& c : node["corners_3d"]) {
        target.corners_3d.push_back(Point3(c, "target.corners_3d"));
      }
    }
    if (node["markers"]) {
      for (const YAML::Node& m : node["markers"]) {
        TargetMarker marker;
        marker.id = Get<int>(m, "id");
        int k = 0;
        for (const YAML::Node& c : m["corners_3d"]) {
          if (k < 4) marker.corners[k] = Point3(c, "target.markers.corners_3d");
          ++k;
        }
        if (k != 4) Fail("target.markers", "expected 4 corners");
        target.markers.push_back(marker);
      }
    }
    if (node["faces"]) {
      for (const YAML::Node& f : node["faces"]) {
        TargetFace face;
        face.name = Get<std::string>(f, "name");
        face.target_from_face = Pose(f, "target_from_face");
        if (f["extent_xy"]) {
          const auto x = f["extent_xy"][0].as<std::vector<double>>();
          const auto y = f["extent_xy"][1].as<std::vector<double>>();
          if (x.size() != 2 || y.size() != 2)
            Fail("target.faces extent_xy", "expected two pairs of numbers");
          face.extent_x = {x[0], x[1]};
          face.extent_y = {y[0], y[1]};
        }
        face.marker_id = Get<int>(f, "marker_id");
        face.marker_side = Finite(f, "marker_side");
        if (f["marker_module"]) face.marker_module = Finite(f, "marker_module");
        if (f["quiet_zone"]) face.quiet_zone = Finite(f, "quiet_zone");
        if (f["num_dots"]) face.num_dots = Get<int>(f, "num_dots");
        TargetMarker marker;
        marker.id = face.marker_id;
        int k = 0;
        for (const YAML::Node& c : f["marker_corners_3d"]) {
          if (k < 4) marker.corners[k] = Point3(c, "target.faces.marker_corners_3d");
          ++k;
        }
        if (k != 4) Fail("target.faces." + face.name, "expected 4 marker corners");
        target.markers.push_back(marker);
        target.faces.push_back(face);
      }
    }
    return target;
  }

 private:
  std::string path_;
};

// --- writing ---------------------------------------------------------------

// Shortest text that reads back as the same double.
std::string Num(double value) {
  char buffer[32];
  for (int precision = 15; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  std::string text = buffer;
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

template <typename Vector>
std::string List(const Vector& v) {
  std::string text = "[";
  for (int i = 0; i < static_cast<int>(v.size()); ++i) {
    if (i > 0) text += ", ";
    text += Num(v[i]);
  }
  return text + "]";
}

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

void WritePose(std::ostream& out, const std::string& indent, const std::string& key,
               const Rigid3d& pose) {
  Eigen::Quaterniond q = pose.rotation.normalized();
  if (q.w() < 0) q.coeffs() *= -1.0;  // w >= 0, as the format states
  out << indent << key << ":\n"
      << indent << "  rotation_wxyz: " << List(QuaternionToWxyz(q)) << "\n"
      << indent << "  translation: " << List(pose.translation) << "\n";
}

void WriteCamera(std::ostream& out, const std::string& indent, const std::string& key,
                 const Camera& camera) {
  out << indent << key << ":\n"
      << indent << "  model: " << camera.ModelName() << "\n"
      << indent << "  width: " << camera.width << "\n"
      << indent << "  height: " << camera.height << "\n"
      << indent << "  params: " << List(camera.params) << "\n"
      << indent << "  param_names: [" << camera.ParamsInfo() << "]\n";
}

void WriteHousing(std::ostream& out, const std::string& indent, const std::string& key,
                  const std::optional<Housing>& housing) {
  if (!housing) {
    out << indent << key << ": null\n";
    return;
  }
  out << indent << key << ":\n"
      << indent << "  model: " << housing->ModelName() << "\n"
      << indent << "  params: " << List(housing->params) << "\n"
      << indent << "  param_names: [" << housing->ParamsInfo() << "]\n";
}

void WriteImage(std::ostream& out, const std::string& indent, const ImageTruth& image) {
  out << indent << "file: " << image.file << "\n";
  WritePose(out, indent, "cam_from_target", image.cam_from_target);
  if (!image.corners_px.empty()) {
    out << indent << "corners_px:\n";
    for (const auto& c : image.corners_px) {
      out << indent << "- " << (c ? List(*c) : std::string("null")) << "\n";
    }
  }
  if (!image.corners_visible.empty()) {
    out << indent << "corners_visible: [";
    for (size_t i = 0; i < image.corners_visible.size(); ++i) {
      out << (i ? ", " : "") << (image.corners_visible[i] ? "true" : "false");
    }
    out << "]\n";
  }
  if (!image.markers.empty()) {
    out << indent << "markers:\n";
    for (const auto& m : image.markers) {
      out << indent << "- id: " << m.id << "\n" << indent << "  corners_px:\n";
      for (const auto& c : m.corners_px) out << indent << "  - " << List(c) << "\n";
      out << indent << "  fully_inside: " << (m.fully_inside ? "true" : "false") << "\n";
    }
  }
}

void WriteTarget(std::ostream& out, const TargetDescription& t) {
  out << "target:\n  type: " << t.type << "\n";
  if (t.type == "chessboard" || t.type == "charuco") {
    out << "  inner_corners_cols: " << t.inner_corners_cols << "\n"
        << "  inner_corners_rows: " << t.inner_corners_rows << "\n"
        << "  squares_cols: " << t.inner_corners_cols + 1 << "\n"
        << "  squares_rows: " << t.inner_corners_rows + 1 << "\n"
        << "  square_size: " << Num(t.square_size) << "\n"
        << "  margin: " << Num(t.margin) << "\n";
  }
  if (t.type == "chessboard") {
    out << "  first_square_color: black (the square touching inner corner 0 diagonally, at "
           "x,y in [-square,0])\n"
        << "  corner_order: index = r * inner_corners_cols + c, point = (c*square, r*square, 0)\n";
  }
  if (t.type == "aruco_grid") {
    out << "  markers_x: " << t.markers_x << "\n  markers_y: " << t.markers_y << "\n"
        << "  marker_separation: " << Num(t.marker_separation) << "\n"
        << "  margin: " << Num(t.margin) << "\n";
  }
  if (!t.aruco_dictionary.empty()) out << "  aruco_dict: " << t.aruco_dictionary << "\n";
  if (t.marker_size > 0) out << "  marker_size: " << Num(t.marker_size) << "\n";
  if (t.type == "target3d") {
    out << "  layout: " << t.layout << "\n  num_faces: " << t.faces.size() << "\n"
        << "  fold_angle_deg: " << Num(t.fold_angle_deg) << "\n"
        << "  face_width: " << Num(t.face_width) << "\n"
        << "  face_height: " << Num(t.face_height) << "\n"
        << "  marker_corner_order: top-left, top-right, bottom-right, bottom-left of the "
           "printed marker (cv2.aruco.detectMarkers order)\n"
        << "  dots_file: " << t.dots_file << "\n  faces:\n";
    for (size_t f = 0; f < t.faces.size(); ++f) {
      const TargetFace& face = t.faces[f];
      out << "  - name: " << face.name << "\n";
      WritePose(out, "    ", "target_from_face", face.target_from_face);
      out << "    extent_xy:\n    - " << List(face.extent_x) << "\n    - " << List(face.extent_y)
          << "\n    marker_id: " << face.marker_id << "\n    marker_side: " << Num(face.marker_side)
          << "\n    marker_module: " << Num(face.marker_module)
          << "\n    quiet_zone: " << Num(face.quiet_zone) << "\n    marker_corners_3d:\n";
      for (const auto& c : t.markers.at(f).corners) out << "    - " << List(c) << "\n";
      out << "    num_dots: " << face.num_dots << "\n";
    }
  } else if (!t.markers.empty()) {
    out << "  markers:\n";
    for (const TargetMarker& m : t.markers) {
      out << "  - id: " << m.id << "\n    corners_3d:\n";
      for (const auto& c : m.corners) out << "    - " << List(c) << "\n";
    }
  }
  if (!t.corners_3d.empty()) {
    out << "  corners_3d:\n";
    for (const auto& c : t.corners_3d) out << "  - " << List(c) << "\n";
  }
}

}  // namespace

namespace {

// The body of ReadGroundTruth; yaml-cpp's exceptions (a key looked up in a scalar, a
// value of the wrong type) are turned into InputError by the caller.
GroundTruth ReadGroundTruthUnguarded(const fs::path& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  const Reader reader(path);
  if (reader.Get<std::string>(root, "format") != "refrender-ground-truth") {
    reader.Fail("format", "expected refrender-ground-truth");
  }
  if (reader.Get<int>(root, "version") != 1) reader.Fail("version", "expected 1");
  GroundTruth truth;
  truth.name = reader.Get<std::string>(root, "name");
  if (root["description"]) truth.description = root["description"].as<std::string>();
  if (root["seed"]) truth.seed = root["seed"].as<int64_t>();
  truth.camera = reader.ReadCamera(root, "camera");
  truth.housing = reader.ReadHousing(root, "housing");
  if (root["stereo"] && !root["stereo"].IsNull()) {
    const YAML::Node s = root["stereo"];
    StereoTruth stereo;
    stereo.cam2_from_cam1 = reader.Pose(s, "cam2_from_cam1");
    stereo.camera2 = reader.ReadCamera(s, "camera2");
    stereo.housing2 = reader.ReadHousing(s, "housing2");
    if (s["baseline"]) stereo.baseline = reader.Finite(s, "baseline");
    if (s["image_dirs"]) {
      const auto dirs = s["image_dirs"].as<std::vector<std::string>>();
      if (dirs.size() != 2) reader.Fail("stereo.image_dirs", "expected 2");
      stereo.image_dirs = {dirs[0], dirs[1]};
    }
    truth.stereo = stereo;
  }
  if (!root["target"]) reader.Fail("target", "missing");
  truth.target = reader.ReadTarget(root["target"]);
  if (!root["images"]) reader.Fail("images", "missing");
  for (const YAML::Node& node : root["images"]) {
    FrameTruth frame;
    frame.frame = reader.Get<int>(node, "frame");
    const std::string where = "images[" + std::to_string(frame.frame) + "]";
    if (truth.stereo) {
      frame.cam1 = reader.ReadImage(node["cam1"], where + ".cam1");
      frame.cam2 = reader.ReadImage(node["cam2"], where + ".cam2");
    } else {
      frame.cam1 = reader.ReadImage(node, where);
    }
    if (!truth.target.corners_3d.empty() && !frame.cam1.corners_px.empty() &&
        frame.cam1.corners_px.size() != truth.target.corners_3d.size()) {
      reader.Fail(where + ".corners_px", "count differs from target.corners_3d");
    }
    truth.images.push_back(frame);
  }
  return truth;
}

}  // namespace

GroundTruth ReadGroundTruth(const fs::path& path) {
  try {
    return ReadGroundTruthUnguarded(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

void WriteGroundTruth(const GroundTruth& truth, const fs::path& path,
                      const std::string& extra_yaml) {
  std::ostringstream out;
  out << "format: refrender-ground-truth\nversion: 1\nname: " << truth.name << "\n"
      << "description: " << Quote(truth.description) << "\n"
      << "generator: portcal synthesize\n"
      << "conventions:\n"
      << "  camera_frame: x right, y down, z forward (COLMAP/OpenCV)\n"
      << "  pixel_coordinates: 'COLMAP: image corner (0,0); centre of the top-left pixel is "
         "(0.5,0.5); OpenCV pixel = COLMAP pixel - 0.5'\n"
      << "  pose: 'a_from_b maps frame-b coordinates into frame a: X_a = R X_b + t; rotation "
         "as unit quaternion (w,x,y,z), Hamilton, w >= 0'\n"
      << "  rig_frame: rig frame = camera 1 frame; cam2_from_target = cam2_from_cam1 * "
         "cam1_from_target\n"
      << "  units: metres, gray levels 0-255\n"
      << "  camera_models: COLMAP model names and parameter orders\n"
      << "  housing_models: FLATPORT (Nx,Ny,Nz,int_dist,int_thick,na,ng,nw), DOMEPORT "
         "(Cx,Cy,Cz,int_radius,int_thick,na,ng,nw) as in the refractive COLMAP fork of "
         "calibmar\n"
      << "seed: " << truth.seed << "\n"
      << "image_size: [" << truth.camera.width << ", " << truth.camera.height << "]\n";
  WriteCamera(out, "", "camera", truth.camera);
  WriteHousing(out, "", "housing", truth.housing);
  if (truth.stereo) {
    out << "stereo:\n";
    WritePose(out, "  ", "cam2_from_cam1", truth.stereo->cam2_from_cam1);
    WriteCamera(out, "  ", "camera2", truth.stereo->camera2);
    WriteHousing(out, "  ", "housing2", truth.stereo->housing2);
    out << "  baseline: " << Num(truth.stereo->baseline) << "\n"
        << "  image_dirs: [" << truth.stereo->image_dirs[0] << ", " << truth.stereo->image_dirs[1]
        << "]\n";
  } else {
    out << "stereo: null\n";
  }
  WriteTarget(out, truth.target);
  out << extra_yaml;
  out << "images:\n";
  for (const FrameTruth& frame : truth.images) {
    out << "- frame: " << frame.frame << "\n";
    if (frame.cam2) {
      out << "  cam1:\n";
      WriteImage(out, "    ", frame.cam1);
      out << "  cam2:\n";
      WriteImage(out, "    ", *frame.cam2);
    } else {
      WriteImage(out, "  ", frame.cam1);
    }
  }
  const std::string text = out.str();
  WriteFileAtomically(path, false, [&](std::ostream& file) { file << text; });
}

}  // namespace portcal
