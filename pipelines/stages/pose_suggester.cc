#include "pipelines/stages/pose_suggester.h"

#include <filesystem>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/detection/detection_rows.h"
#include "pipelines/guidance/pose_preview.h"

namespace fs = std::filesystem;

namespace portcal {

void PoseSuggesterOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a folder for the suggestions");
  CheckOutputFolder("--output_path", output_path);
  if (num_poses < 1) throw OptionError("--num_poses", num_poses, ">= 1");
  if (housing.has_value() != !input_calibration.empty()) {
    throw OptionError(housing ? "--input_calibration" : "--Housing.model", "''",
                      "both --input_calibration and --Housing.model for a housing calibration, "
                      "neither for a camera's");
  }
  target.Check();
  guidance.Check();
}

namespace {

struct DatabaseViews {
  Camera camera;
  std::vector<CalibrationView> views;
  std::string target;  // as target_extractor described it; "" without views
};

// The camera's views so far (none in a database without observations).
DatabaseViews ReadViews(const PoseSuggesterOptions& options) {
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  DatabaseViews result;
  std::optional<camera_t> camera_id;
  if (options.camera_id >= 0) camera_id = static_cast<camera_t>(options.camera_id);
  // No views yet is a plan from nothing; a damaged one is an error.
  const TargetViews views = ReadTargetViewsIfAny(&database);
  if (!views.by_camera.empty() &&
      (options.camera_id < 0 || views.by_camera.count(static_cast<camera_t>(options.camera_id)))) {
    camera_id = ChooseCamera(views, options.camera_id, options.database_path);
    result.views = views.by_camera.at(*camera_id);
    result.target = views.target;
  } else {
    const std::vector<Camera> cameras = database.ReadAllCameras();
    if (!camera_id && cameras.size() == 1) camera_id = cameras[0].camera_id;
  }
  const std::optional<Camera> camera = camera_id ? database.ReadCamera(*camera_id) : std::nullopt;
  if (!camera) {
    throw InputError(options.database_path + ": no camera" +
                     (options.camera_id >= 0 ? " " + std::to_string(options.camera_id)
                                             : std::string(" to choose")) +
                     " (import images first: live_calibrator or target_extractor)");
  }
  result.camera = *camera;
  // Poses of another board than the views' would be planned in the wrong
  // units and shape.
  const std::string asked = TargetDescriptionText(options.target);
  if (!result.target.empty() && result.target != asked) {
    throw InputError(options.database_path + ": its views are of the target '" + result.target +
                     "', the --Target.* options describe '" + asked + "'");
  }
  return result;
}

std::string PoseLine(int index, const PoseSuggestion& pose) {
  const Rigid3d& p = pose.cam_from_target;
  std::ostringstream line;
  line << std::setprecision(9) << index << " " << p.rotation.w() << " " << p.rotation.x() << " "
       << p.rotation.y() << " " << p.rotation.z() << " " << p.translation.x() << " "
       << p.translation.y() << " " << p.translation.z() << " " << std::setprecision(4)
       << (pose.after.determined ? pose.after.mean_px : -1.0) << " # " << pose.why << "\n";
  return line.str();
}

void WriteSuggestions(const PoseSuggesterOptions& options, const HousedCamera& camera,
                      const TargetShape& target, const std::vector<PoseSuggestion>& poses) {
  const fs::path dir(options.output_path);
  fs::create_directories(dir);
  std::string text =
      "# The next target poses: INDEX QW QX QY QZ TX TY TZ EXPECTED_UNCERTAINTY_PX # WHY\n"
      "# cam_from_target (target frame -> camera frame, metres); the expected projection "
      "uncertainty (mean over\n"
      "# the image, 1 sigma, px) once this and the poses before it are added; -1: still "
      "undetermined.\n";
  for (size_t k = 0; k < poses.size(); ++k) {
    text += PoseLine(static_cast<int>(k + 1), poses[k]);
    std::ostringstream name, caption;
    name << "suggested_pose_" << std::setw(2) << std::setfill('0') << k + 1 << ".png";
    caption << "pose " << k + 1 << ": " << poses[k].why;
    const fs::path partial = dir / ("." + name.str() + ".partial.png");
    if (!cv::imwrite(partial.string(),
                     PosePreview(camera, target, poses[k].cam_from_target, caption.str()))) {
      throw InputError(partial.string() + ": cannot write the preview");
    }
    fs::rename(partial, dir / name.str());
  }
  WriteFileAtomically(dir / "suggested_poses.txt", false, [&](std::ostream& out) { out << text; });
}

}  // namespace

PoseSuggesterSummary RunPoseSuggester(const PoseSuggesterOptions& options, ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  const DatabaseViews data = ReadViews(options);
  LiveEstimatorOptions estimator_options;
  estimator_options.camera = data.camera;
  estimator_options.fixed_params = options.fixed_params;
  estimator_options.guidance = options.guidance;
  if (options.housing) {
    estimator_options.camera = ReadCalibrationReport(options.input_calibration).camera;
    estimator_options.housing = options.housing;
  }
  const LiveEstimator estimator(estimator_options, ShapeOfTarget(options.target));
  progress.Begin("pose_suggester: poses", static_cast<size_t>(options.num_poses));
  PoseSuggesterSummary summary;
  summary.estimate = estimator.Estimate(data.views, nullptr);
  LOG(INFO) << "pose_suggester: from " << summary.estimate.Summary();
  NextPoseOptions guidance = options.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, summary.estimate.pixel_sigma_px);
  summary.poses = SuggestPoses(estimator.Unknowns(summary.estimate.camera), estimator.target(),
                               summary.estimate.information, summary.estimate.num_views,
                               options.num_poses, guidance);
  progress.Advance(static_cast<size_t>(options.num_poses));
  progress.End();
  WriteSuggestions(options, summary.estimate.camera, estimator.target(), summary.poses);
  LOG(INFO) << "pose_suggester: " << summary.poses.size() << " poses -> " << options.output_path;
  new_output.Keep();
  return summary;
}

}  // namespace portcal
