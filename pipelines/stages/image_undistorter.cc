#include "pipelines/stages/image_undistorter.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/confined_path.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "colmap_ext/util/parallel.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/stereo_calibration_file.h"
#include "pipelines/images/image_reader.h"
#include "pipelines/undistortion/dense_workspace.h"
#include "pipelines/undistortion/remap_tables.h"
#include "pipelines/undistortion/undistortion_plan.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

struct ImageToUndistort {
  std::string name;  // relative to image_path
  camera_t camera_id = 0;
};

// What to undistort: a model's cameras and registered images (with poses),
// a calibration file's camera (id 1) for every image of the folder, or a
// stereo calibration's two cameras (ids 1, 2) for the images of the
// folder's first and second subfolder.
struct UndistortionInput {
  SparseModel model;
  std::vector<ImageToUndistort> images;
  bool has_poses = false;
  std::optional<Rigid3d> cam2_from_cam1;
};

void AddCamera(const HousedCamera& camera, camera_t id, SparseModel* model) {
  model->cameras[id] = camera.camera;
  model->cameras[id].camera_id = id;
  if (camera.housing) model->housings[id] = *camera.housing;
}

// A rig's images: the first subfolder's (by name) are camera 1's, the
// second's camera 2's.
void ReadStereoInput(const ImageUndistorterOptions& options, UndistortionInput* input) {
  const StereoCalibrationFile rig = ReadStereoCalibrationFile(options.input_path);
  AddCamera(rig.camera1, 1, &input->model);
  AddCamera(rig.camera2, 2, &input->model);
  input->cam2_from_cam1 = rig.cam2_from_cam1;
  std::vector<std::string> folders;
  for (const std::string& name : ListImages(options.image_path)) {
    const std::string folder = fs::path(name).begin()->string();
    if (folder == name) continue;  // a file beside the folders
    if (std::find(folders.begin(), folders.end(), folder) == folders.end())
      folders.push_back(folder);
    const auto index = std::find(folders.begin(), folders.end(), folder) - folders.begin();
    if (index < 2) input->images.push_back({name, static_cast<camera_t>(index + 1)});
  }
  if (folders.size() != 2) {
    throw InputError(options.image_path +
                     ": a stereo calibration needs the images in two folders (camera 1's, "
                     "then camera 2's by name, e.g. cam1/ and cam2/); found " +
                     std::to_string(folders.size()));
  }
}

UndistortionInput ReadInput(const ImageUndistorterOptions& options) {
  UndistortionInput input;
  if (fs::is_directory(options.input_path)) {
    input.model = ReadSparseModel(options.input_path);
    input.has_poses = true;
    for (const auto& [image_id, image] : input.model.images)
      input.images.push_back({image.name, image.camera_id});
  } else if (!fs::exists(options.input_path)) {
    throw InputError(options.input_path + ": no such file or directory");
  } else if (IsStereoCalibrationFile(options.input_path)) {
    ReadStereoInput(options, &input);
  } else {
    const CalibrationReport report = ReadCalibrationReport(options.input_path);
    AddCamera({report.camera, report.housing}, 1, &input.model);
    for (const std::string& name : ListImages(options.image_path))
      input.images.push_back({name, 1});
  }
  if (input.images.empty() && input.has_poses)
    throw InputError(options.input_path + ": the model has no images");
  // Names come from the model: each must stay inside --image_path when read
  // and inside the output's images/ when written, before any work.
  for (const ImageToUndistort& image : input.images) {
    ConfinedPath(options.image_path, image.name, "image name in " + options.input_path);
    ConfinedPath(fs::path(options.output_path) / "images", image.name,
                 "image name in " + options.input_path);
  }
  size_t missing = 0;
  std::string first_missing;
  for (const ImageToUndistort& image : input.images) {
    if (fs::is_regular_file(fs::path(options.image_path) / image.name)) continue;
    if (missing++ == 0) first_missing = (fs::path(options.image_path) / image.name).string();
  }
  if (missing > 0) {
    throw InputError(first_missing + ": no such image (" + std::to_string(missing) + " of the " +
                     std::to_string(input.images.size()) + " images of " + options.input_path +
                     " are missing from --image_path)");
  }
  return input;
}

void UndistortImages(const ImageUndistorterOptions& options,
                     const std::vector<ImageToUndistort>& images,
                     const std::map<camera_t, RemapTables>& tables, const SparseModel& model,
                     const fs::path& folder, ProgressSink& progress) {
  for (const ImageToUndistort& image : images)
    fs::create_directories((folder / image.name).parent_path());
  progress.Begin("undistorted images", images.size());
  ParallelFor(images.size(), options.num_threads, [&](size_t i) {
    const fs::path path = fs::path(options.image_path) / images[i].name;
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (image.empty()) throw InputError(path.string() + ": not an image OpenCV can read");
    const Camera& camera = model.cameras.at(images[i].camera_id);
    cv::Mat output;
    try {
      output = ApplyRemapTables(
          tables.at(images[i].camera_id), image,
          cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)));
    } catch (const InputError& e) {
      throw InputError(path.string() + ": " + e.what() + " (camera " +
                       std::to_string(camera.camera_id) + ")");
    }
    if (!cv::imwrite((folder / images[i].name).string(), output)) {
      throw InputError((fs::path(options.output_path) / "images" / images[i].name).string() +
                       ": OpenCV cannot write it");
    }
    progress.Advance(1);
  });
  progress.End();
}

// Every entry of `staging` replaces its namesake in `output`.
void MoveIntoPlace(const fs::path& staging, const fs::path& output) {
  for (const fs::directory_entry& entry : fs::directory_iterator(staging)) {
    fs::remove_all(output / entry.path().filename());
    fs::rename(entry.path(), output / entry.path().filename());
  }
  fs::remove_all(staging);
}

void WriteReports(const ImageUndistorterSummary& summary, const fs::path& staging) {
  WriteFileAtomically(staging / "undistortion.txt", false, [&](std::ostream& out) {
    out << UndistortionReportText(summary.cameras, summary.warnings);
  });
  WriteFileAtomically(staging / "undistortion.yaml", false, [&](std::ostream& out) {
    out << UndistortionReportYaml(summary.cameras, summary.warnings);
  });
  fs::create_directories(staging / "report");
  WriteHtmlReport(UndistortionHtml(summary.cameras, summary.warnings), staging / "report");
}

}  // namespace

void ImageUndistorterOptions::Check() const {
  if (input_path.empty())
    throw OptionError("--input_path", "''", "a sparse model folder or a calibration file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "the folder of the images");
  if (output_path.empty())
    throw OptionError("--output_path", "''", "the workspace folder to write");
  CheckOutputFolder("--output_path", output_path);
  UndistortionPlanOptions::Check();
  if (!(max_error_px > 0))
    throw OptionError("--Undistort.max_error_px", FormatShortest(max_error_px), "> 0");
}

// The run itself; RunImageUndistorter names what a stop leaves.
static ImageUndistorterSummary Run(const ImageUndistorterOptions& options, ProgressSink& progress) {
  options.Check();
  const UndistortionInput input = ReadInput(options);
  ImageUndistorterSummary summary;
  summary.num_images = input.images.size();
  summary.cameras = PlanUndistortion(options, input.model, input.cam2_from_cam1);
  std::map<camera_t, VirtualPinhole> pinholes;
  std::map<camera_t, RemapTables> tables;
  for (const CameraUndistortion& camera : summary.cameras) {
    const camera_t id = camera.pinhole.pinhole.camera_id;
    pinholes[id] = camera.pinhole;
    tables[id] = ComputeRemapTables(camera.pinhole, options.num_threads, progress);
  }
  summary.warnings = UndistortionWarnings(summary.cameras, options.max_error_px);
  const fs::path output(options.output_path), staging = output / ".image_undistorter_staging";
  NewPaths new_paths({output, staging});
  fs::remove_all(staging);
  UndistortImages(options, input.images, tables, input.model, staging / "images", progress);
  SparseModel pinhole_model = PinholeModel(input.model, pinholes);
  if (input.has_poses) {
    WriteDenseWorkspace(pinhole_model, staging);
  } else {
    WriteSparseModel(pinhole_model, staging / "sparse",
                     ModelFormat::kBinary);  // the camera; no poses to hand on
  }
  if (options.write_maps) {
    fs::create_directories(staging / "maps");
    for (const auto& [camera_id, pinhole] : pinholes) {
      WriteRemapTables(tables.at(camera_id), pinhole,
                       staging / "maps" / ("camera_" + std::to_string(camera_id) + ".yaml.gz"));
    }
  }
  WriteReports(summary, staging);
  // The last moment to honour a stop; after it the output is replaced.
  if (CancelFlag::Requested()) throw Cancelled("nothing was written to " + options.output_path);
  MoveIntoPlace(staging, output);
  new_paths.Keep();
  for (const std::string& warning : summary.warnings) LOG(WARNING) << warning;
  LOG(INFO) << summary.num_images << " images undistorted into " << options.output_path
            << " (report: " << (output / "undistortion.txt").string() << ")";
  return summary;
}

ImageUndistorterSummary RunImageUndistorter(const ImageUndistorterOptions& options,
                                            ProgressSink& progress) {
  try {
    return Run(options, progress);
  } catch (const Cancelled&) {
    throw Cancelled("nothing was written to " + options.output_path);  // not "the database"
  }
}

}  // namespace portcal
