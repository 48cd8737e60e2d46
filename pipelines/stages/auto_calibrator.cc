#include "pipelines/stages/auto_calibrator.h"

#include <chrono>
#include <set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_output.h"
#include "pipelines/markers/aruco.h"
#include "pipelines/report/calibration_html.h"
#include "pipelines/sfm/calibration_start.h"

namespace fs = std::filesystem;

namespace portcal {

void AutoCalibratorOptions::Check() const {
  if (image_path.empty()) throw OptionError("--image_path", "''", "a directory of images");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a directory for the results");
  CheckOutputFolder("--output_path", output_path);
  if (housing) housing->ValidateInput("--Housing.params");
  CheckArucoDictionaryOption("--Markers.dictionary", marker_dictionary);
  if (matcher == PairingMode::kSpatial) {
    throw OptionError("--AutoCalibration.matcher", "spatial", "exhaustive or sequential");
  }
  if (random_seed < 0) throw OptionError("--random_seed", random_seed, ">= 0");
  if (max_num_starts < 1) {
    throw OptionError("--AutoCalibration.max_num_starts", max_num_starts, ">= 1");
  }
  marker_scale.Check();
}

namespace {

// Without given intrinsics the database camera starts at the image reader's
// guess (1.2 x the larger image side). Two-view verification estimates E on
// rays normalised with it, so a wrong guess shapes which pairs and inliers
// the mapper gets (docs/dev/auto_calibration_notes.md). The markers give a far better
// start: it is written to the database camera before matching.
// Returns the markers' focal length (in-air equivalent), or nullopt.
std::optional<double> WriteMarkersFocalToDatabase(const std::string& database_path,
                                                  const std::optional<Housing>& housing) {
  Database database(database_path, Database::OpenMode::kReadWrite);
  const SfmInputs inputs = SfmInputs::Read(&database);
  std::map<camera_t, HousedCamera> cameras = inputs.cameras;
  if (housing) ReplaceHousings(*housing, &cameras);
  StartFocalFromMarkers(inputs, true, &cameras);
  Transaction transaction = database.BeginTransaction();
  std::optional<double> focal;
  for (const auto& [id, camera] : cameras) {
    if (camera.camera.params != inputs.cameras.at(id).camera.params)
      focal = camera.camera.MeanFocalLength();
    database.UpdateCamera(camera.camera);
  }
  transaction.Commit();
  return focal;
}

ModelMappingOptions MapperOptions(const AutoCalibratorOptions& options, int random_seed,
                                  bool refine_intrinsics,
                                  const std::set<image_pair_t>& excluded_pairs) {
  ModelMappingOptions map;
  map.mapper.init_excluded_pairs = excluded_pairs;
  map.housing = options.housing;
  map.mapper.num_threads = options.num_threads;
  map.mapper.random_seed = random_seed;
  map.init_radial_from_matches = options.init_radial_from_matches;
  map.init_focal_from_pairs = options.init_focal_from_pairs;
  map.mapper.marker_scale = options.marker_scale;
  map.mapper.ba_refine_focal_length = refine_intrinsics;
  map.mapper.ba_refine_extra_params = refine_intrinsics;
  const bool refine_principal_point = refine_intrinsics && options.refine_principal_point != false;
  // A port's orientation (a flat port's tilt), under the untilted guess, is
  // absorbed by the mapper's poses and points unless the port is refined as
  // the model grows. A dome's centred guess is close, and its axial decentering
  // trades with the focal length on a few views, so it is left to the final
  // refinement. Only with marker scale: without it the port distance is
  // barely observed and refining it splits the models
  // (docs/dev/auto_calibration_notes.md).
  map.mapper.ba_refine_housing = options.housing &&
                                 !options.housing->Refinement().orientation.empty() &&
                                 options.marker_scale.side_length_m > 0;
  // The principal point with it: held at the image centre when it is not
  // there, the global adjustments fight the port. With the dome left to the
  // final refinement, its principal point is too (refined in the mapper,
  // dome renders came out worse). The final refinement decides whether it
  // stays off the centre (docs/dev/auto_calibration_notes.md).
  map.mapper.ba_refine_principal_point = refine_principal_point && map.mapper.ba_refine_housing;
  return map;
}

ModelRefinementOptions RefinerOptions(const AutoCalibratorOptions& options,
                                      bool refine_intrinsics) {
  const bool refine_principal_point = refine_intrinsics && options.refine_principal_point != false;
  ModelRefinementOptions refine;
  refine.marker_scale = options.marker_scale;
  refine.housing_guess = options.housing;
  refine.ba.refine_housing = options.housing.has_value();
  refine.ba.refine_focal_length = refine_intrinsics;
  refine.ba.refine_extra_params = refine_intrinsics;
  // A camera's principal point is rarely exactly at the image centre, and
  // held there when it is not, the port absorbs the offset
  // (docs/dev/auto_calibration_notes.md). Held at the centre again unless it lies
  // beyond 3 sigma from it.
  refine.ba.refine_principal_point = refine_principal_point;
  refine.principal_point_test_sigmas = options.refine_principal_point.has_value() ? 0.0 : 3.0;
  refine.ba.num_threads = options.num_threads;
  return refine;
}

// The camera the stages made (one, shared by all images).
camera_t OnlyCameraId(Database* database, const std::string& database_path) {
  const std::vector<Camera> cameras = database->ReadAllCameras();
  if (cameras.size() != 1) {
    throw DatabaseError(database_path + ": " + std::to_string(cameras.size()) +
                        " cameras; auto_calibrator writes one back");
  }
  return cameras.front().camera_id;
}

}  // namespace

AutoCalibratorSummary RunAutoCalibrator(const AutoCalibratorOptions& options,
                                        ProgressSink& progress) {
  options.Check();
  const fs::path output(options.output_path);
  // A failed run removes what it made (the folder if it was not there, the
  // database, the models); the stages inside roll back their own writes.
  NewPaths new_paths({output, output / "database.db", output / "sparse", output / "refined"});
  fs::create_directories(output);
  const std::string database_path = (output / "database.db").string();
  const bool intrinsics_given = !options.camera_params.empty();
  const bool refine_intrinsics = options.refine_intrinsics.value_or(!intrinsics_given);
  AutoCalibratorSummary result;
  auto clock = std::chrono::steady_clock::now();
  const auto lap = [&](const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    result.stage_seconds.emplace_back(stage, std::chrono::duration<double>(now - clock).count());
    clock = now;
  };

  FeatureExtractorOptions extract;
  extract.database_path = database_path;
  extract.image_path = options.image_path;
  extract.reader.camera_model = options.camera_model;
  extract.reader.single_camera = true;
  extract.reader.camera_params = options.camera_params;
  extract.sift = options.sift;
  extract.num_threads = options.num_threads;
  result.num_images = RunFeatureExtractor(extract, progress).num_images;
  lap("feature_extractor");

  if (options.mask) {
    FeatureMaskerOptions mask;
    mask.database_path = database_path;
    mask.image_path = options.image_path;
    mask.dictionary = options.marker_dictionary;
    mask.enlargement_factor = options.mask_enlargement_factor;
    mask.num_threads = options.num_threads;
    RunFeatureMasker(mask, progress);
    lap("feature_masker");
  }

  std::optional<double> markers_focal;
  if (!intrinsics_given)
    markers_focal = WriteMarkersFocalToDatabase(database_path, options.housing);

  FeatureMatcherOptions match;
  match.database_path = database_path;
  match.mode = options.matcher;
  match.num_threads = options.num_threads;
  match.verification.random_seed = options.random_seed;
  RunFeatureMatcher(match, progress);
  lap(PairingModeName(options.matcher) + "_matcher");

  const CalibrationStart best = [&] {
    // The matched database read once for every start (as refractive_mapper
    // reads it), its models handed over in memory.
    Database database(database_path, Database::OpenMode::kReadOnly);
    const SfmInputs inputs = SfmInputs::Read(&database);
    if (inputs.pair_inliers.empty()) {
      throw InputError(database_path + ": no verified image pairs; run a matcher first");
    }
    CalibrationStartsOptions starts;
    starts.map = MapperOptions(options, options.random_seed, refine_intrinsics, {});
    starts.refine = RefinerOptions(options, refine_intrinsics);
    starts.refine_intrinsics = refine_intrinsics;
    starts.max_num_starts = options.max_num_starts;
    starts.output_path = options.output_path;
    starts.database_path = database_path;
    return BestStart(starts, inputs, markers_focal, progress);
  }();
  result.refined = best.refined;
  result.num_registered = best.num_registered;
  lap("refractive_mapper + refractive_bundle_adjuster");
  std::optional<Database> database;
  if (options.update_database) database.emplace(database_path, Database::OpenMode::kReadWrite);
  const SparseModel& refined = best.model;
  // Judged again: the report gained this stage's own warnings.
  result.refined.report.verdict = JudgeCalibration(
      result.refined.report, refined, refined.cameras.empty() ? 0 : refined.cameras.begin()->first);
  WriteCalibrationOutput(
      result.refined.report, options.output_path, database ? &*database : nullptr,
      database ? OnlyCameraId(&*database, database_path) : kInvalidCameraId, [&] {
        WriteHtml(SelfCalibrationHtml(result.refined.report, refined, "Auto-calibration"),
                  options.output_path);
      });
  std::string times;
  for (const auto& [stage, seconds] : result.stage_seconds)
    times += " " + stage + " " + std::to_string(seconds) + " s;";
  LOG(INFO) << "auto_calibrator: " << result.num_registered << " of " << result.num_images
            << " images calibrated; times:" << times;
  new_paths.Keep();
  return result;
}

}  // namespace portcal
