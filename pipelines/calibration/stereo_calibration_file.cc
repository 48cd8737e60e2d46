#include "pipelines/calibration/stereo_calibration_file.h"

#include <yaml-cpp/yaml.h>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

YAML::Node Load(const fs::path& path) {
  if (!fs::is_regular_file(path)) throw InputError(path.string() + ": no such file");
  try {
    return YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

const YAML::Node Required(const YAML::Node& node, const std::string& key,
                          const std::string& context) {
  if (!node.IsMap() || !node[key]) throw InputError(context + ": no key '" + key + "'");
  return node[key];
}

HousedCamera ReadCamera(const YAML::Node& root, const std::string& key, camera_t id,
                        const std::string& file) {
  const std::string context = file + ": " + key;
  const YAML::Node block = Required(root, key, file);
  HousedCamera camera;
  camera.camera.camera_id = id;
  try {
    camera.camera.model_id =
        CameraModelNameToId(Required(block, "model", context).as<std::string>());
  } catch (const InputError& e) {
    throw InputError(context + ".model: " + e.what());
  }
  camera.camera.params = Required(block, "parameters", context).as<std::vector<double>>();
  camera.camera.width = Required(block, "width", context).as<uint64_t>();
  camera.camera.height = Required(block, "height", context).as<uint64_t>();
  camera.camera.Validate(context);
  if (block["non_svp_model"] && block["non_svp_model"].as<std::string>() != "NONE") {
    camera.housing =
        Housing::FromName(block["non_svp_model"].as<std::string>(),
                          Required(block, "non_svp_parameters", context).as<std::vector<double>>(),
                          context + ".non_svp_parameters");
    camera.housing->ValidateInput(context + ".non_svp_parameters");
  }
  return camera;
}

Rigid3d ReadPose(const YAML::Node& root, const std::string& file) {
  const std::string context = file + ": cam2_from_cam1";
  const YAML::Node block = Required(root, "cam2_from_cam1", file);
  const std::vector<double> q = Required(block, "rotation_wxyz", context).as<std::vector<double>>();
  const std::vector<double> t = Required(block, "translation", context).as<std::vector<double>>();
  if (q.size() != 4 || t.size() != 3)
    throw InputError(context + ": rotation_wxyz needs 4 values, translation 3");
  const Eigen::Vector4d wxyz(q[0], q[1], q[2], q[3]);
  const Eigen::Vector3d translation(t[0], t[1], t[2]);
  if (!wxyz.allFinite() || !(wxyz.norm() > 1e-6) || !translation.allFinite()) {
    throw InputError(context + ": not a rotation and translation (non-finite or zero quaternion)");
  }
  if (!(translation.norm() > 0))
    throw InputError(context + ": the two cameras are in one place (zero baseline)");
  return Rigid3d(QuaternionFromWxyz(wxyz.normalized()), translation);
}

}  // namespace

bool IsStereoCalibrationFile(const fs::path& path) {
  try {
    const YAML::Node root = YAML::LoadFile(path.string());
    return root.IsMap() && root["cam2_from_cam1"];
  } catch (const YAML::Exception&) {
    return false;
  }
}

StereoCalibrationFile ReadStereoCalibrationFile(const fs::path& path) {
  const YAML::Node root = Load(path);
  try {
    StereoCalibrationFile file;
    file.camera1 = ReadCamera(root, "camera1", 1, path.string());
    file.camera2 = ReadCamera(root, "camera2", 2, path.string());
    file.cam2_from_cam1 = ReadPose(root, path.string());
    return file;
  } catch (const YAML::Exception& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

}  // namespace portcal
