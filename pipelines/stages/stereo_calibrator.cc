#include "pipelines/stages/stereo_calibrator.h"

#include <filesystem>
#include <map>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/report/calibration_html.h"

namespace fs = std::filesystem;

namespace portcal {

void StereoCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  CheckOutputFolder("--output_path", output_path);
  if (pairing != "name" && pairing != "order")
    throw OptionError("--Stereo.pairing", pairing, "name or order");
  if (camera1_id >= 0 && camera1_id == camera2_id) {
    throw OptionError("--Stereo.camera2_id", camera2_id, "another camera than --Stereo.camera1_id");
  }
  if (input_calibration1.empty() != input_calibration2.empty()) {
    throw OptionError("--input_calibration1/2",
                      input_calibration1.empty() ? input_calibration2 : input_calibration1,
                      "both or neither");
  }
  stereo.Check();
}

namespace {

HousedCamera CameraFor(const std::string& input_calibration, const Camera& database_camera,
                       const std::vector<CalibrationView>& views, int num_threads) {
  if (!input_calibration.empty()) {
    const CalibrationReport report = ReadCalibrationReport(input_calibration);
    return {report.camera, report.housing};
  }
  CameraCalibrationSettings settings;
  settings.num_threads = num_threads;
  CameraCalibrationResult result;
  try {
    result = CalibrateCamera(views, database_camera, settings);
  } catch (const NumericalError& e) {
    throw NumericalError("camera " + std::to_string(database_camera.camera_id) +
                         " (calibrated first from its " + std::to_string(views.size()) +
                         " views): " + e.what());
  }
  LOG(INFO) << "stereo_calibrator: camera " << database_camera.camera_id
            << " calibrated first, RMS " << result.overall_rms_px << " px";
  return {result.camera, std::nullopt};
}

}  // namespace

StereoCalibratorSummary RunStereoCalibrator(const StereoCalibratorOptions& options,
                                            ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  TargetViews target_views = ReadTargetViews(&database);
  auto& views_by_camera = target_views.by_camera;
  std::vector<camera_t> ids;
  for (const auto& [id, views] : views_by_camera) ids.push_back(id);
  camera_t id1 = static_cast<camera_t>(options.camera1_id),
           id2 = static_cast<camera_t>(options.camera2_id);
  if (options.camera1_id < 0 || options.camera2_id < 0) {
    if (ids.size() != 2) {
      throw InputError(
          options.database_path + ": " + std::to_string(ids.size()) +
          " cameras have target observations; choose --Stereo.camera1_id and "
          "--Stereo.camera2_id (extract with --ImageReader.single_camera_per_folder 1)");
    }
    id1 = ids[0];
    id2 = ids[1];
  }
  for (const auto& [id, option] :
       {std::pair(id1, "--Stereo.camera1_id"), std::pair(id2, "--Stereo.camera2_id")}) {
    if (!views_by_camera.count(id)) {
      throw InputError(options.database_path + ": camera " + std::to_string(id) + " (" + option +
                       ") has no target observations");
    }
  }
  const std::vector<CalibrationView>& views1 = views_by_camera[id1];
  const std::vector<CalibrationView>& views2 = views_by_camera[id2];
  std::vector<StereoFrame> frames;
  if (options.pairing == "name") {
    std::map<std::string, const CalibrationView*> by_name;
    for (const CalibrationView& v : views2)
      by_name[fs::path(v.image_name).filename().string()] = &v;
    for (const CalibrationView& v : views1) {
      const auto it = by_name.find(fs::path(v.image_name).filename().string());
      if (it != by_name.end()) frames.push_back({v, *it->second});
    }
  } else {
    for (size_t i = 0; i < std::min(views1.size(), views2.size()); ++i)
      frames.push_back({views1[i], views2[i]});
  }
  LOG(INFO) << "stereo_calibrator: cameras " << id1 << " and " << id2 << ", " << frames.size()
            << " frames paired by " << options.pairing;
  if (frames.empty()) {
    throw InputError(
        options.database_path +
        ": no frame in which both cameras see the target (--Stereo.pairing " + options.pairing +
        ": " +
        (options.pairing == "name" ? "the same file name in both cameras' folders)" : "by order)"));
  }
  const HousedCamera camera1 = CameraFor(options.input_calibration1, *database.ReadCamera(id1),
                                         views1, options.stereo.num_threads);
  const HousedCamera camera2 = CameraFor(options.input_calibration2, *database.ReadCamera(id2),
                                         views2, options.stereo.num_threads);
  const StereoCalibrationResult result = CalibrateStereo(frames, camera1, camera2, options.stereo);
  std::vector<CalibrationView> used1, used2;
  for (const StereoFrame& frame : frames) {
    used1.push_back(frame.cam1);
    used2.push_back(frame.cam2);
  }
  const CalibrationVerdict verdict = JudgeStereo(result, used1, used2);
  const std::string text = WriteStereoCalibrationReport(
      result, camera1, camera2, target_views.target, options.output_path, &verdict);
  HtmlReport html = StereoCalibrationHtml(result, used1, used2, text);
  html.verdict = HtmlVerdictOf(verdict);
  WriteHtml(html, options.output_path);
  LOG(INFO) << "stereo_calibrator: baseline " << result.cam2_from_cam1.translation.norm()
            << " m, RMS " << result.overall_rms_px << " px -> " << options.output_path;
  new_output.Keep();
  return result;
}

}  // namespace portcal
