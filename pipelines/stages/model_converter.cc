#include "pipelines/stages/model_converter.h"

#include <filesystem>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/opencv_camera_file.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/confined_path.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {
namespace {

bool IsModelType(const std::string& type) { return type == "BIN" || type == "TXT"; }

bool HasExtension(const std::string& path, const std::string& extension) {
  return std::filesystem::path(path).extension() == extension;
}

// The input as a sparse model: a model directory, or a single camera (id 1)
// from a .cameramodel or a calibration.yaml (with its housing).
SparseModel ReadInput(const std::string& path) {
  if (std::filesystem::is_directory(path)) return ReadSparseModel(path);
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file or directory");
  SparseModel model;
  Camera camera;
  if (HasExtension(path, ".cameramodel")) {
    camera = ReadMrcalCameraModel(path).camera;
  } else if (HasExtension(path, ".yaml") || HasExtension(path, ".yml")) {
    const CalibrationReport report = ReadCalibrationReport(path);
    camera = report.camera;
    if (report.housing) model.housings[1] = *report.housing;
  } else {
    throw InputError(path + ": expected a model directory, a .cameramodel or a calibration.yaml");
  }
  camera.camera_id = 1;
  model.cameras[1] = camera;
  return model;
}

const Camera& ChooseCamera(const SparseModel& model, int camera_id, const std::string& input) {
  if (camera_id >= 0) {
    const auto it = model.cameras.find(static_cast<camera_t>(camera_id));
    if (it == model.cameras.end()) {
      throw InputError(input + ": no camera " + std::to_string(camera_id) + " (--camera_id)");
    }
    return it->second;
  }
  if (model.cameras.size() != 1) {
    throw InputError(input + ": " + std::to_string(model.cameras.size()) +
                     " cameras; choose one with --camera_id");
  }
  return model.cameras.begin()->second;
}

}  // namespace

void ModelConverterOptions::Check() const {
  if (input_path.empty()) {
    throw OptionError("--input_path", "''", "a model directory, .cameramodel or calibration.yaml");
  }
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory or file");
  if (!IsModelType(output_type) && output_type != "CAMERAMODEL" && output_type != "OPENCV_YAML" &&
      output_type != "ROS_YAML") {
    throw OptionError("--output_type", output_type,
                      "BIN, TXT, CAMERAMODEL, OPENCV_YAML or ROS_YAML");
  }
  if (IsModelType(output_type)) {
    CheckOutputFolder("--output_path", output_path);
  } else {
    CheckOutputFile("--output_path", output_path, {input_path});
  }
}

ModelConverterSummary RunModelConverter(const ModelConverterOptions& options,
                                        ProgressSink& progress) {
  options.Check();
  const SparseModel model = ReadInput(options.input_path);
  NewPaths new_output({options.output_path});  // a failed run leaves no output it made
  std::string summary;
  if (IsModelType(options.output_type)) {
    WriteSparseModel(model, options.output_path,
                     options.output_type == "BIN" ? ModelFormat::kBinary : ModelFormat::kText);
    summary = std::to_string(model.cameras.size()) + " cameras, " +
              std::to_string(model.images.size()) + " images, " +
              std::to_string(model.points3D.size()) + " points, " +
              std::to_string(model.housings.size()) + " housings written as " +
              options.output_type + " to " + options.output_path;
  } else {
    const Camera& camera = ChooseCamera(model, options.camera_id, options.input_path);
    if (model.housings.count(camera.camera_id)) {
      LOG(WARNING) << options.input_path << ": camera " << camera.camera_id
                   << " sits behind a housing; " << options.output_type
                   << " carries the in-air lens only";
    }
    if (options.output_type == "CAMERAMODEL") {
      WriteMrcalCameraModel(camera, Rigid3d(), options.output_path);
      LOG(INFO) << options.output_path
                << " holds the lens only; the camera.cameramodel camera_calibrator "
                << "writes also holds the solve (mrcal's optimization_inputs) for mrcal's "
                   "uncertainty tools";
    } else if (options.output_type == "OPENCV_YAML") {
      WriteOpenCvCameraYaml(camera, options.output_path);
    } else {
      WriteRosCameraInfoYaml(camera, "camera" + std::to_string(camera.camera_id),
                             options.output_path);
    }
    summary = "camera " + std::to_string(camera.camera_id) + " (" + camera.ModelName() +
              ") written as " + options.output_type + " to " + options.output_path;
  }
  new_output.Keep();
  LOG(INFO) << summary;
  return {summary};
}

}  // namespace portcal
