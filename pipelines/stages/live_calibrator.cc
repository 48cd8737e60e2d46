#include "pipelines/stages/live_calibrator.h"

#include <filesystem>
#include <iomanip>
#include <set>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/new_database_file.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/detection/detection_rows.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/housing_calibrator.h"

namespace fs = std::filesystem;

namespace portcal {

void LiveCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "a folder for the kept frames");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a folder for the reports");
  if (housing.has_value() != !input_calibration.empty()) {
    throw OptionError(housing ? "--input_calibration" : "--Housing.model", "''",
                      "both --input_calibration and --Housing.model for a housing calibration, neither for a camera's");
  }
  reader.Check();
  live.Check();
  page.Check();
}

namespace {

// Kept frames as files and rows: the file is moved into place first, then
// the rows are committed (a failed commit removes the file again).
class DatabaseFrameStore : public KeptFrameStore {
 public:
  DatabaseFrameStore(const LiveCalibratorOptions& options, Database* database)
      : options_(options), database_(database), target_(TargetDescriptionText(options.live.detector)) {
    reader_ = options.reader;
    reader_.single_camera = true;
    reader_.single_camera_per_folder = false;
    // A continued session: the new frames join the camera of the kept ones
    // (a frame of another size is then refused, naming both).
    std::set<camera_t> cameras;
    for (const DatabaseImage& image : database->ReadAllImages()) cameras.insert(image.camera_id);
    if (cameras.size() == 1) shared_.by_folder[""] = *cameras.begin();
  }

  std::string Store(const cv::Mat& image, const TargetDetection& detection) override {
    const std::string name = NextName();
    const fs::path path = fs::path(options_.image_path) / name;
    const fs::path partial = fs::path(options_.image_path) / ("." + name + ".partial.png");
    std::error_code error;
    // At the first keep: a session that keeps nothing leaves nothing.
    fs::create_directories(options_.image_path, error);
    if (error || !cv::imwrite(partial.string(), image)) {
      throw InputError(partial.string() + ": cannot write the frame" + (error ? " (" + error.message() + ")" : ""));
    }
    fs::rename(partial, path, error);
    if (error) throw InputError(path.string() + ": cannot move the frame into place (" + error.message() + ")");
    try {
      Transaction transaction = database_->BeginTransaction();
      const image_t id = ImportImage(database_, reader_, name, image.cols, image.rows, &shared_);
      WriteTargetDetection(database_, id, detection, target_);
      transaction.Commit();
    } catch (...) {
      std::error_code ignored;
      fs::remove(path, ignored);
      throw;
    }
    return name;
  }

  // The rows go; the file is renamed NAME.removed (no image extension, so
  // no later import sees it), not deleted.
  void Remove(const std::string& name) override {
    Transaction transaction = database_->BeginTransaction();
    const std::optional<DatabaseImage> image = database_->ReadImageWithName(name);
    if (!image) throw InputError(name + ": not in " + options_.database_path);
    database_->DeleteImage(image->image_id);
    transaction.Commit();
    const fs::path path = fs::path(options_.image_path) / name;
    std::error_code ignored;
    fs::rename(path, fs::path(path.string() + ".removed"), ignored);
  }

 private:
  // live_NNNN.png after the highest such name in the folder or database.
  std::string NextName() {
    while (true) {
      std::ostringstream name;
      name << "live_" << std::setw(4) << std::setfill('0') << ++counter_ << ".png";
      const fs::path path = fs::path(options_.image_path) / name.str();
      if (!fs::exists(path) && !fs::exists(path.string() + ".removed") && !database_->ReadImageWithName(name.str())) {
        return name.str();
      }
    }
  }

  const LiveCalibratorOptions& options_;
  Database* database_;
  std::string target_;
  ImageReaderOptions reader_;
  SharedCameras shared_;
  int counter_ = 0;

 public:
  // The camera the kept frames share (-1 before the first).
  int camera_id() const {
    const auto it = shared_.by_folder.find("");
    return it == shared_.by_folder.end() ? -1 : static_cast<int>(it->second);
  }
};

// Views a previous session kept in this database (a continued session),
// with their corners' ids, so that hands-free capture does not keep them
// again.
std::vector<KeptView> ExistingViews(Database* database) {
  std::vector<KeptView> kept;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    KeptView view;
    view.name = image.name;
    view.view.image_name = image.name;
    for (const TargetObservation& o : database->ReadTargetObservations(image.image_id)) {
      view.view.points_in_target.push_back(o.point_in_target);
      view.view.pixels.push_back(o.xy);
      view.corners[static_cast<int>(o.point_id)] = o.xy;
    }
    if (!view.view.pixels.empty()) kept.push_back(view);
  }
  return kept;
}

// The estimator's start: the in-air calibration (housing) or the model
// alone, sized by the first frame (camera).
LiveSessionOptions SessionOptions(const LiveCalibratorOptions& options, ImageReaderOptions* reader) {
  LiveSessionOptions live = options.live;
  live.estimator.fixed_params = options.fixed_params;
  if (options.housing) {
    const CalibrationReport in_air = ReadCalibrationReport(options.input_calibration);
    live.estimator.camera = in_air.camera;
    live.estimator.housing = options.housing;
    std::ostringstream params;
    params.precision(17);
    for (size_t k = 0; k < in_air.camera.params.size(); ++k) params << (k ? "," : "") << in_air.camera.params[k];
    reader->camera_model = in_air.camera.ModelName();
    reader->camera_params = params.str();
  } else {
    live.estimator.camera = Camera::FromModelName(options.reader.camera_model, 1.0, 0, 0);
  }
  return live;
}

// The final reports, by the batch calibrators on the database.
void CalibrateAtEnd(const LiveCalibratorOptions& options, int camera_id, ProgressSink& progress,
                    LiveCalibratorSummary* summary) {
  if (options.housing) {
    HousingCalibratorOptions housing;
    housing.database_path = options.database_path;
    housing.input_calibration = options.input_calibration;
    housing.output_path = options.output_path;
    housing.housing = options.housing;
    housing.camera_id = camera_id;
    summary->housing = RunHousingCalibrator(housing, progress);
    return;
  }
  CameraCalibratorOptions camera;
  camera.database_path = options.database_path;
  camera.output_path = options.output_path;
  camera.camera_id = camera_id;
  camera.calibration.fixed_params = options.fixed_params;
  summary->camera = RunCameraCalibrator(camera, progress);
}

struct SessionOutcome {
  LiveSummary summary;
  int camera_id = -1;  // of the kept frames
  int num_views = 0;   // in the database
};

// The session, with the database open only while it runs.
SessionOutcome RunSession(const LiveCalibratorOptions& options, const LiveSessionOptions& live,
                          const std::function<void(LiveSession&, const std::string&)>& on_start) {
  NewDatabaseFile new_file(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  { Transaction probe = database.BeginTransaction(); }  // fails now, not at the first keep, when locked
  DatabaseFrameStore store(options, &database);
  LiveSession session(live, &store, ExistingViews(&database));
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
  outcome.num_views = static_cast<int>(database.NumImages());
  if (outcome.num_views > 0) new_file.Keep();
  outcome.camera_id = store.camera_id();
  return outcome;
}

}  // namespace

LiveCalibratorSummary RunLiveCalibrator(const LiveCalibratorOptions& options, ProgressSink& progress,
                                        const std::function<void(LiveSession&, const std::string&)>& on_start) {
  options.Check();
  LiveCalibratorOptions adjusted = options;
  adjusted.page.output_path = options.output_path;
  const LiveSessionOptions live = SessionOptions(options, &adjusted.reader);
  const SessionOutcome outcome = RunSession(adjusted, live, on_start);
  LiveCalibratorSummary summary;
  summary.session = outcome.summary;
  const int views = outcome.num_views;
  if (summary.session.end_reason == "interrupted") {
    throw Cancelled(std::to_string(views) + " views kept in " + options.database_path + " and " +
                    options.image_path +
                    " (calibrate them with camera_calibrator / housing_calibrator, or rerun to add more)");
  }
  if (!options.calibrate_at_end) return summary;
  const int needed = options.housing ? 2 : 3;
  if (views < needed) {
    throw NumericalError("live_calibrator: " + std::to_string(views) + " views kept (" + summary.session.end_reason +
                         "); a calibration needs " + std::to_string(needed) + ". They stay in " +
                         options.database_path + "; rerun to add more");
  }
  CalibrateAtEnd(options, outcome.camera_id, progress, &summary);
  summary.calibrated = true;
  return summary;
}

}  // namespace portcal
