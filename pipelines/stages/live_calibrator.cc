#include "pipelines/stages/live_calibrator.h"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "colmap_ext/util/confined_path.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/new_database_file.h"
#include "database/session_lock.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/live/database_frame_store.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/housing_calibrator.h"
#include "pipelines/stages/stereo_calibrator.h"

namespace fs = std::filesystem;

namespace portcal {

void LiveCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "a folder for the kept frames");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a folder for the reports");
  if (housing.has_value() != !input_calibration.empty()) {
    throw OptionError(housing ? "--input_calibration" : "--Housing.model", "''",
                      "both --input_calibration and --Housing.model for a housing calibration, "
                      "neither for a camera's");
  }
  if (!input_calibration2.empty() && !live.Stereo()) {
    throw OptionError("--input_calibration2", input_calibration2,
                      "only with --source2 (a stereo rig)");
  }
  if (live.Stereo() && housing && input_calibration2.empty()) {
    throw OptionError("--input_calibration2", "''",
                      "camera 2's in-air calibration.yaml (a rig behind housings)");
  }
  reader.Check();
  live.Check();
  page.Check();
}

namespace {

// The folder of each camera's kept frames below --image_path: none for one
// camera, cam1/ and cam2/ for a rig (a camera per folder, as
// target_extractor imports a rig and stereo_calibrator pairs it by name).
std::vector<std::string> CameraFolders(const LiveCalibratorOptions& options) {
  return options.live.Stereo() ? std::vector<std::string>{"cam1", "cam2"}
                               : std::vector<std::string>{""};
}

// A camera's import options: the model alone (camera calibration) or its
// in-air calibration, which the estimator also starts from.
ImageReaderOptions ReaderFor(const ImageReaderOptions& reader, const std::string& input_calibration,
                             Camera* start) {
  ImageReaderOptions result = reader;
  if (input_calibration.empty()) {
    *start = Camera::FromModelName(reader.camera_model, 1.0, 0, 0);  // sized by the first frame
    return result;
  }
  *start = ReadCalibrationReport(input_calibration).camera;
  std::ostringstream params;
  params.precision(17);
  for (size_t k = 0; k < start->params.size(); ++k) params << (k ? "," : "") << start->params[k];
  result.camera_model = start->ModelName();
  result.camera_params = params.str();
  return result;
}

// The estimators' starts (a rig's camera 2 behind a housing of the same
// kind, from the same start) and each camera's import options.
LiveSessionOptions SessionOptions(const LiveCalibratorOptions& options,
                                  std::vector<ImageReaderOptions>* readers) {
  LiveSessionOptions live = options.live;
  live.estimator.fixed_params = options.fixed_params;
  live.estimator.housing = options.housing;
  readers->push_back(ReaderFor(options.reader, options.input_calibration, &live.estimator.camera));
  if (live.Stereo()) {
    live.housing2 = options.housing;
    readers->push_back(ReaderFor(options.reader, options.input_calibration2, &live.camera2));
  }
  return live;
}

// One camera's final report, by the batch calibrators on the database.
void CalibrateCameraAtEnd(const LiveCalibratorOptions& options, int camera_id,
                          const std::string& input_calibration, const std::string& output_path,
                          ProgressSink& progress,
                          std::optional<CameraCalibrationResult>* camera_result,
                          std::optional<HousingCalibrationResult>* housing_result) {
  if (options.housing) {
    HousingCalibratorOptions housing;
    housing.database_path = options.database_path;
    housing.input_calibration = input_calibration;
    housing.output_path = output_path;
    housing.housing = options.housing;
    housing.camera_id = camera_id;
    housing.calibration.estimate_board_warp = options.live.estimator.estimate_board_warp;
    *housing_result = RunHousingCalibrator(housing, progress);
    return;
  }
  CameraCalibratorOptions camera;
  camera.database_path = options.database_path;
  camera.output_path = output_path;
  camera.camera_id = camera_id;
  camera.calibration.fixed_params = options.fixed_params;
  camera.calibration.estimate_board_warp = options.live.estimator.estimate_board_warp;
  *camera_result = RunCameraCalibrator(camera, progress);
}

// The final reports: one camera's in --output_path; a rig's cameras in
// OUT/cam1 and OUT/cam2, then stereo_calibrator from those into OUT
// (with --Stereo.refine_intrinsics 1 for a camera calibration).
void CalibrateAtEnd(const LiveCalibratorOptions& options, const std::vector<int>& camera_ids,
                    ProgressSink& progress, LiveCalibratorSummary* summary) {
  if (camera_ids.size() == 1) {
    CalibrateCameraAtEnd(options, camera_ids[0], options.input_calibration, options.output_path,
                         progress, &summary->camera, &summary->housing);
    return;
  }
  const fs::path out(options.output_path);
  CalibrateCameraAtEnd(options, camera_ids[0], options.input_calibration, (out / "cam1").string(),
                       progress, &summary->camera, &summary->housing);
  CalibrateCameraAtEnd(options, camera_ids[1], options.input_calibration2, (out / "cam2").string(),
                       progress, &summary->camera2, &summary->housing2);
  StereoCalibratorOptions stereo;
  stereo.database_path = options.database_path;
  stereo.output_path = options.output_path;
  stereo.camera1_id = camera_ids[0];
  stereo.camera2_id = camera_ids[1];
  stereo.input_calibration1 = (out / "cam1" / "calibration.yaml").string();
  stereo.input_calibration2 = (out / "cam2" / "calibration.yaml").string();
  // The intrinsics come from these very frames: refined with the rig, so
  // that the rig's standard deviations carry their uncertainty (held, a
  // few pairs' intrinsics errors would hide in a confident baseline). A
  // housing calibration holds the in-air intrinsics it was given.
  stereo.stereo.refine_intrinsics = !options.housing.has_value();
  summary->stereo = RunStereoCalibrator(stereo, progress);
}

struct SessionOutcome {
  LiveSummary summary;
  std::vector<int> camera_ids;  // of the kept frames, per camera
  int num_views = 0;            // kept views in the database (a rig's pairs)
};

// What follows the session (the final calibration), run while the page
// still serves; returns the line the page shows.
using Conclusion = std::function<std::string(const SessionOutcome&)>;

// The final calibration with the page told what happens: a page polls
// every 0.4 s, so it gets the outcome before the server goes (it keeps
// showing it after portcal exits). Not after Ctrl-C: the person is at the
// terminal.
void Conclude(const SessionOutcome& outcome, const Conclusion& conclude, LiveSession* session,
              bool page) {
  const auto linger = [page] {
    if (page) std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  };
  session->SetFinalStatus("calibrating the kept views ...");
  try {
    session->SetFinalStatus(conclude(outcome));
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception& e) {
    session->SetFinalStatus(std::string("no calibration: ") + e.what());
    linger();
    throw;
  }
  linger();
}

// The session, then `conclude`, with the database open (idle) and the page
// serving until both are done.
SessionOutcome RunSession(const LiveCalibratorOptions& options, const LiveSessionOptions& live,
                          const std::vector<ImageReaderOptions>& readers,
                          const std::function<void(LiveSession&, const std::string&)>& on_start,
                          const Conclusion& conclude) {
  NewDatabaseFile new_file(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  const SessionLock one_session(options.database_path, "live_calibrator session");
  {
    Transaction probe = database.BeginTransaction();
  }  // fails now, not at the first keep, when locked
  DatabaseFrameStore store(&database, options.image_path, options.live.detector,
                           CameraFolders(options), readers);
  LiveSession session(live, &store, ExistingViews(&database, CameraFolders(options)));
  std::optional<LiveServer> page;
  if (!options.page.headless) page.emplace(&session, options.page);
  if (on_start) on_start(session, page ? page->url() : std::string());
  SessionOutcome outcome;
  try {
    outcome.summary = session.Run();
  } catch (...) {
    // A source that fails mid-session: what was kept stays.
    if (database.NumImages() > 0) new_file.Keep();
    throw;
  }
  if (database.NumImages() > 0) new_file.Keep();
  outcome.num_views = static_cast<int>(ExistingViews(&database, CameraFolders(options)).size());
  outcome.camera_ids = store.camera_ids();
  Conclude(outcome, conclude, &session, page.has_value());
  return outcome;
}

// After the session: Cancelled after Ctrl-C, else the final calibration
// (NumericalError with too few views), and the line that says how it went.
std::string FinalCalibration(const LiveCalibratorOptions& options, const SessionOutcome& outcome,
                             ProgressSink& progress, LiveCalibratorSummary* summary) {
  const int views = outcome.num_views;
  const std::string what = options.live.Stereo() ? " pairs" : " views";
  if (outcome.summary.end_reason == "interrupted") {
    throw Cancelled(
        std::to_string(views) + what + " kept in " + options.database_path + " and " +
        options.image_path + " (calibrate them with camera_calibrator / housing_calibrator" +
        (options.live.Stereo() ? " and stereo_calibrator" : "") + ", or rerun to add more)");
  }
  if (!options.calibrate_at_end)
    return std::to_string(views) + what + " kept; not calibrated (--calibrate_at_end 0)";
  const int needed = options.housing ? 2 : 3;
  if (views < needed) {
    throw NumericalError("live_calibrator: " + std::to_string(views) + what + " kept (" +
                         outcome.summary.end_reason + "); a calibration needs " +
                         std::to_string(needed) + ". They stay in " + options.database_path +
                         "; rerun to add more");
  }
  CalibrateAtEnd(options, outcome.camera_ids, progress, summary);
  summary->calibrated = true;
  std::ostringstream line;
  line << std::setprecision(3) << "reports in " << options.output_path << " (" << views << what;
  const auto rms = [&line](const char* which, const auto& result) {
    if (result) line << "; " << which << "RMS " << result->overall_rms_px << " px";
  };
  rms(options.live.Stereo() ? "camera 1 " : "", summary->camera);
  rms(options.live.Stereo() ? "camera 1 " : "", summary->housing);
  rms("camera 2 ", summary->camera2);
  rms("camera 2 ", summary->housing2);
  if (summary->stereo) {
    line << "; baseline " << std::setprecision(5)
         << 1000 * summary->stereo->cam2_from_cam1.translation.norm() << " mm ± "
         << std::setprecision(2) << 1000 * summary->stereo->translation_std_dev.norm() << " mm";
  }
  line << ")";
  return line.str();
}

}  // namespace

LiveCalibratorSummary RunLiveCalibrator(
    const LiveCalibratorOptions& options, ProgressSink& progress,
    const std::function<void(LiveSession&, const std::string&)>& on_start) {
  options.Check();
  LiveCalibratorOptions adjusted = options;
  adjusted.page.output_path = options.output_path;
  std::vector<ImageReaderOptions> readers;
  const LiveSessionOptions live = SessionOptions(options, &readers);
  LiveCalibratorSummary summary;
  const SessionOutcome outcome = RunSession(
      adjusted, live, readers, on_start,
      [&](const SessionOutcome& o) { return FinalCalibration(options, o, progress, &summary); });
  summary.session = outcome.summary;
  return summary;
}

}  // namespace portcal
