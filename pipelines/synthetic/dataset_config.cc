#include "pipelines/synthetic/dataset_config.h"

#include <yaml-cpp/yaml.h>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {

namespace {

// A rendered image is held with its supersamples in memory: 10^8 pixels
// (100 megapixels, above any camera here) bounds one frame to a few GB.
constexpr double kMaxRenderPixels = 1e8;

void CheckRenderArea(const Camera& camera, const std::string& key) {
  const double area = static_cast<double>(camera.width) * static_cast<double>(camera.height);
  if (area > kMaxRenderPixels) {
    throw OptionError(key + ".width x height",
                      std::to_string(camera.width) + " x " + std::to_string(camera.height),
                      "at most 10^8 pixels (100 megapixels) per image");
  }
}

}  // namespace

void DatasetConfig::Check() const {
  if (num_images < 1) throw OptionError("num_images", num_images, ">= 1");
  camera.Validate("camera");
  CheckRenderArea(camera, "camera");
  if (housing) housing->ValidateInput("housing");
  if (stereo) {
    camera2.Validate("stereo.camera2");
    CheckRenderArea(camera2, "stereo.camera2");
    if (housing2) housing2->ValidateInput("stereo.housing2");
  }
  if (survey) {
    survey_options.Check();
  } else {
    target.Check();
    poses.Check();
  }
  render.Check();
  if (trajectory) {
    trajectory->Check();
  }
  if (!(clutter_distance_m > 0)) {
    throw OptionError("clutter.distance", clutter_distance_m, "> 0 m");
  }
  if (!(occlusion_probability >= 0 && occlusion_probability <= 1)) {
    throw OptionError("occlusion.probability", occlusion_probability, "[0, 1]");
  }
  if (!(occlusion_fraction > 0 && occlusion_fraction < 0.9)) {
    throw OptionError("occlusion.fraction", occlusion_fraction, "(0, 0.9)");
  }
}

namespace {

class ConfigReader {
 public:
  explicit ConfigReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw InputError(path_ + ": " + key + ": " + what);
  }

  template <typename T>
  void Optional(const YAML::Node& node, const std::string& prefix, const char* key,
                T* value) const {
    if (!node || !node[key] || node[key].IsNull()) return;
    try {
      *value = node[key].as<T>();
    } catch (const YAML::Exception& e) {
      Fail(prefix + key, e.what());
    }
  }

  Camera ReadCamera(const YAML::Node& node, const std::string& key) const {
    if (!node || node.IsNull()) Fail(key, "missing");
    Camera camera;
    std::string model;
    Optional(node, key + ".", "model", &model);
    try {
      camera.model_id = CameraModelNameToId(model);
    } catch (const InputError& e) {
      Fail(key + ".model", e.what());
    }
    int width = 0, height = 0;
    Optional(node, key + ".", "width", &width);
    Optional(node, key + ".", "height", &height);
    if (width <= 0 || height <= 0) Fail(key + ".width/height", "must be positive");
    camera.width = width;
    camera.height = height;
    Optional(node, key + ".", "params", &camera.params);
    camera.Validate(path_ + ": " + key);
    return camera;
  }

  std::optional<Housing> ReadHousing(const YAML::Node& node, const std::string& key) const {
    if (!node || node.IsNull()) return std::nullopt;
    std::string model;
    std::vector<double> params;
    Optional(node, key + ".", "model", &model);
    Optional(node, key + ".", "params", &params);
    if (model.empty() || model == "NONE") return std::nullopt;
    return Housing::FromName(model, params, path_ + ": " + key);
  }

  Rigid3d ReadPose(const YAML::Node& node, const std::string& key) const {
    if (!node) Fail(key, "missing");
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    std::vector<double> values;
    if (node["rotation_wxyz"]) {
      Optional(node, key + ".", "rotation_wxyz", &values);
      if (values.size() != 4) Fail(key + ".rotation_wxyz", "expected 4 numbers");
      rotation = Eigen::Quaterniond(values[0], values[1], values[2], values[3]).normalized();
    } else if (node["rotation_axis_angle_deg"]) {
      Optional(node, key + ".", "rotation_axis_angle_deg", &values);
      if (values.size() != 4)
        Fail(key + ".rotation_axis_angle_deg", "expected axis x, y, z, angle");
      rotation = Eigen::AngleAxisd(values[3] * M_PI / 180.0,
                                   Eigen::Vector3d(values[0], values[1], values[2]).normalized());
    }
    std::vector<double> t;
    Optional(node, key + ".", "translation", &t);
    if (t.size() != 3) Fail(key + ".translation", "expected 3 numbers");
    return Rigid3d(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
  }

  void ReadTarget(const YAML::Node& n, TargetOptions* t) const {
    Optional(n, "target.", "type", &t->type);
    Optional(n, "target.", "cols", &t->cols);
    Optional(n, "target.", "rows", &t->rows);
    Optional(n, "target.", "squares_x", &t->squares_x);
    Optional(n, "target.", "squares_y", &t->squares_y);
    Optional(n, "target.", "square_size", &t->square_size_m);
    Optional(n, "target.", "margin", &t->margin_m);
    Optional(n, "target.", "markers_x", &t->markers_x);
    Optional(n, "target.", "markers_y", &t->markers_y);
    Optional(n, "target.", "marker_size", &t->marker_size_m);
    Optional(n, "target.", "marker_separation", &t->marker_separation_m);
    Optional(n, "target.", "first_marker", &t->first_marker);
    Optional(n, "target.", "dictionary", &t->dictionary);
    Optional(n, "target.", "aruco_dict", &t->dictionary);
    Optional(n, "target.", "num_faces", &t->num_faces);
    Optional(n, "target.", "fold_angle_deg", &t->fold_angle_deg);
    Optional(n, "target.", "face_width", &t->face_width_m);
    Optional(n, "target.", "face_height", &t->face_height_m);
    Optional(n, "target.", "marker_ids", &t->marker_ids);
    if (t->type == "target3d") {
      t->target3d_marker_size_m = 0.06;
      Optional(n, "target.", "marker_size", &t->target3d_marker_size_m);
    }
    Optional(n, "target.", "quiet_zone_modules", &t->quiet_zone_modules);
    const YAML::Node dots = n["dots"];
    int64_t seed = static_cast<int64_t>(t->dots.seed);
    Optional(dots, "target.dots.", "seed", &seed);
    t->dots.seed = static_cast<uint64_t>(seed);
    Optional(dots, "target.dots.", "r_min", &t->dots.r_min_m);
    Optional(dots, "target.dots.", "r_max", &t->dots.r_max_m);
    Optional(dots, "target.dots.", "coverage", &t->dots.coverage);
    Optional(dots, "target.dots.", "gray_min", &t->dots.gray_min);
    Optional(dots, "target.dots.", "gray_max", &t->dots.gray_max);
    Optional(dots, "target.dots.", "edge_margin", &t->dots.edge_margin_m);
  }

  void ReadRender(const YAML::Node& root, ImageFormationOptions* r) const {
    const YAML::Node n = root["render"];
    Optional(n, "render.", "spp", &r->spp);
    Optional(n, "render.", "blur_sigma", &r->blur_sigma_px);
    Optional(n, "render.", "noise_sigma", &r->noise_sigma);
    Optional(n, "render.", "white", &r->levels.white);
    Optional(n, "render.", "black", &r->levels.black);
    Optional(n, "render.", "background", &r->levels.background);
    Optional(n, "render.", "invalid", &r->levels.invalid);
    Optional(n, "render.", "back", &r->levels.back);
    bool jitter = false;
    Optional(n, "render.", "jitter", &jitter);
    if (jitter) Fail("render.jitter", "only stratum centres (jitter: false) are supported");
    const YAML::Node w = root["water"];
    Optional(w, "water.", "attenuation", &r->attenuation_per_m);
    Optional(w, "water.", "backscatter", &r->backscatter_gray);
    Optional(w, "water.", "forward_scatter", &r->forward_scatter_per_m);
    Optional(w, "water.", "forward_scatter_sigma_px", &r->forward_scatter_sigma_px);
    Optional(root, "", "vignetting", &r->vignetting);
    const YAML::Node m = root["motion_blur"];
    std::vector<double> v;
    Optional(m, "motion_blur.", "velocity", &v);
    if (!v.empty()) {
      if (v.size() != 3) Fail("motion_blur.velocity", "expected 3 numbers (m/s, camera frame)");
      r->velocity_m_s = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    v.clear();
    Optional(m, "motion_blur.", "angular_velocity_deg_s", &v);
    if (!v.empty()) {
      if (v.size() != 3) Fail("motion_blur.angular_velocity_deg_s", "expected 3 numbers");
      r->angular_velocity_rad_s = Eigen::Vector3d(v[0], v[1], v[2]) * M_PI / 180.0;
    }
    Optional(m, "motion_blur.", "exposure", &r->exposure_s);
    Optional(m, "motion_blur.", "samples", &r->motion_samples);
  }

 private:
  std::string path_;
};

}  // namespace

namespace {

// The body of ReadDatasetConfig; yaml-cpp's exceptions (a key looked up in a scalar, a
// value of the wrong type) are turned into InputError by the caller.
DatasetConfig ReadDatasetConfigUnguarded(const std::filesystem::path& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  const ConfigReader reader(path.string());
  DatasetConfig config;
  reader.Optional(root, "", "name", &config.name);
  reader.Optional(root, "", "description", &config.description);
  int64_t seed = 1;
  reader.Optional(root, "", "seed", &seed);
  config.seed = static_cast<uint64_t>(seed);
  reader.Optional(root, "", "num_images", &config.num_images);
  config.camera = reader.ReadCamera(root["camera"], "camera");
  config.housing = reader.ReadHousing(root["housing"], "housing");
  if (root["stereo"] && !root["stereo"].IsNull()) {
    const YAML::Node s = root["stereo"];
    config.stereo = true;
    config.cam2_from_cam1 = reader.ReadPose(s["cam2_from_cam1"], "stereo.cam2_from_cam1");
    config.camera2 =
        s["camera2"] ? reader.ReadCamera(s["camera2"], "stereo.camera2") : config.camera;
    config.housing2 =
        s["housing2"] ? reader.ReadHousing(s["housing2"], "stereo.housing2") : config.housing;
  }
  if (root["survey"] && !root["survey"].IsNull()) {
    const YAML::Node s = root["survey"];
    SurveyOptions& o = config.survey_options;
    config.survey = true;
    reader.Optional(s, "survey.", "height", &o.height_m);
    reader.Optional(s, "survey.", "speed", &o.speed_m_s);
    reader.Optional(s, "survey.", "frame_rate", &o.frame_rate_hz);
    reader.Optional(s, "survey.", "side_overlap", &o.side_overlap);
    reader.Optional(s, "survey.", "line_length", &o.line_length_m);
    reader.Optional(s, "survey.", "roughness", &o.roughness_m);
    reader.Optional(s, "survey.", "relief_wavelength", &o.relief_wavelength_m);
    reader.Optional(s, "survey.", "texel", &o.texel_m);
    reader.Optional(s, "survey.", "navigation_sigma", &o.navigation_sigma_m);
    if (s["markers"] && !s["markers"].IsNull()) {
      const YAML::Node m = s["markers"];
      reader.Optional(m, "survey.markers.", "count", &o.markers.count);
      reader.Optional(m, "survey.markers.", "side", &o.markers.side_m);
      reader.Optional(m, "survey.markers.", "spacing", &o.markers.spacing_m);
      reader.Optional(m, "survey.markers.", "dictionary", &o.markers.dictionary);
    }
    int64_t texture_seed = static_cast<int64_t>(o.texture_seed);
    reader.Optional(s, "survey.", "seed", &texture_seed);
    o.texture_seed = static_cast<uint64_t>(texture_seed);
    o.num_images = config.num_images;
  } else {
    if (!root["target"]) reader.Fail("target", "missing (or give survey)");
    reader.ReadTarget(root["target"], &config.target);
    const YAML::Node p = root["poses"];
    std::vector<double> distance;
    reader.Optional(p, "poses.", "distance", &distance);
    if (!distance.empty()) {
      if (distance.size() != 2) reader.Fail("poses.distance", "expected [min, max] in metres");
      config.poses.distance_min_m = distance[0];
      config.poses.distance_max_m = distance[1];
    }
    reader.Optional(p, "poses.", "tilt_max_deg", &config.poses.tilt_max_deg);
    reader.Optional(p, "poses.", "roll_max_deg", &config.poses.roll_max_deg);
    reader.Optional(p, "poses.", "border_margin_px", &config.poses.border_margin_px);
    reader.Optional(p, "poses.", "max_view_angle_deg", &config.poses.max_view_angle_deg);
    reader.Optional(p, "poses.", "visibility", &config.poses.visibility);
    if (config.target.type == "target3d" && !(p && p["visibility"]))
      config.poses.visibility = "markers";
    if (root["trajectory"] && !root["trajectory"].IsNull()) {
      const YAML::Node t = root["trajectory"];
      TrajectoryOptions& trajectory = config.trajectory.emplace();
      reader.Optional(t, "trajectory.", "fps", &trajectory.fps);
      reader.Optional(t, "trajectory.", "pauses", &trajectory.num_pauses);
      reader.Optional(t, "trajectory.", "pause_seconds", &trajectory.pause_seconds);
      reader.Optional(t, "trajectory.", "move_seconds", &trajectory.move_seconds);
      reader.Optional(t, "trajectory.", "exposure", &trajectory.exposure_s);
      reader.Optional(t, "trajectory.", "video", &trajectory.video);
    }
  }
  const YAML::Node c = root["clutter"];
  reader.Optional(c, "clutter.", "enabled", &config.clutter);
  reader.Optional(c, "clutter.", "distance", &config.clutter_distance_m);
  int64_t clutter_seed = static_cast<int64_t>(config.clutter_seed);
  reader.Optional(c, "clutter.", "seed", &clutter_seed);
  config.clutter_seed = static_cast<uint64_t>(clutter_seed);
  reader.Optional(c, "clutter.", "num_shapes", &config.clutter_num_shapes);
  const YAML::Node o = root["occlusion"];
  reader.Optional(o, "occlusion.", "probability", &config.occlusion_probability);
  reader.Optional(o, "occlusion.", "fraction", &config.occlusion_fraction);
  reader.ReadRender(root, &config.render);
  try {
    config.Check();
  } catch (const OptionError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  return config;
}

}  // namespace

DatasetConfig ReadDatasetConfig(const std::filesystem::path& path) {
  try {
    return ReadDatasetConfigUnguarded(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

}  // namespace portcal
