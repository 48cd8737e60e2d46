#include "pipelines/stages/auto_calibrator.h"

#include <chrono>
#include <iomanip>
#include <set>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
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
  if (random_seed < 0) throw OptionError("--random_seed", std::to_string(random_seed), ">= 0");
  if (max_num_starts < 1) {
    throw OptionError("--AutoCalibration.max_num_starts", std::to_string(max_num_starts), ">= 1");
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

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(4) << value;
  return out.str();
}

// A focal length with a standard deviation above this fraction of itself
// is not determined by the views (well-posed sets: 0.05-0.5 %).
constexpr double kMaxRelativeFocalStdDev = 0.01;

}  // namespace

// Fails on a focal length the markers rule out; warns, first in the
// report, of what the views leave undetermined.
void JudgeAutoCalibration(const std::optional<double>& markers_focal, CalibrationReport* report) {
  const double focal = report->camera.MeanFocalLength();
  const std::string remedy =
      "give the in-air intrinsics (--ImageReader.camera_params), more views, or views "
      "with wider tilt and nearer the image corners";
  if (markers_focal && !(focal / *markers_focal < kMaxFocalRatioToMarkers &&
                         *markers_focal / focal < kMaxFocalRatioToMarkers)) {
    throw NumericalError(
        "auto_calibrator: the refined focal length " + FormatNumber(focal) +
        " px is far from the ArUco markers' estimate " + FormatNumber(*markers_focal) +
        " px: the reconstruction settled in a wrong solution (lens distortion and housing "
        "traded against each other); " +
        remedy);
  }
  const std::vector<int> focal_idxs = CameraModelFocalLengthIdxs(report->camera.model_id);
  const double focal_std_dev = report->parameters_std_dev.at(focal_idxs.front());
  if (focal_std_dev < 0) {
    report->warnings.push_back("the focal length is undetermined (no finite standard deviation); " +
                               remedy);
    LOG(WARNING) << "auto_calibrator: " << report->warnings.back();
  } else if (focal_std_dev > kMaxRelativeFocalStdDev * focal) {
    report->warnings.push_back("the focal length is poorly determined: std dev " +
                               FormatNumber(focal_std_dev) + " px, " +
                               FormatNumber(100 * focal_std_dev / focal) + " % of it; " + remedy);
    LOG(WARNING) << "auto_calibrator: " << report->warnings.back();
  }
}

namespace {

struct CalibrationStart {
  int index = 0;  // 0: written to output_path itself; k: output_path/start_k
  int num_registered = 0;
  ModelRefinementSummary refined;
  SparseModel model;  // refined
};

std::string StartDir(int k) { return "start_" + std::to_string(k); }

// Warnings another start might cure: not those about what the views'
// geometry cannot tell apart.
size_t NumCurableWarnings(const ModelRefinementSummary& refined) {
  return refined.report.warnings.size() - static_cast<size_t>(refined.num_geometry_warnings);
}

bool BetterStart(const CalibrationStart& a, const CalibrationStart& b) {
  const size_t wa = NumCurableWarnings(a.refined), wb = NumCurableWarnings(b.refined);
  if (wa != wb) return wa < wb;
  return a.refined.report.residual_sigma_px < b.refined.report.residual_sigma_px;
}

// Moves the kept start's sparse/ and refined/ to output_path (kept < 0:
// none) and removes the other starts' folders.
void KeepStart(const fs::path& output_path, int kept, int num_starts) {
  if (kept > 0) {
    for (const char* name : {"sparse", "refined"}) {
      fs::remove_all(output_path / name);
      fs::rename(output_path / StartDir(kept) / name, output_path / name);
    }
  }
  for (int k = 1; k < num_starts; ++k) fs::remove_all(output_path / StartDir(k));
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

// What the database adds to the mapper's model's images, from the inputs
// the mapper read: marker detections, position priors and, where the
// model's points are the database's keypoints, their scales.
void AddExtrasFrom(const std::map<std::string, const SfmImage*>& by_name, SfmImage* image) {
  const auto it = by_name.find(image->name);
  if (it == by_name.end()) return;
  const SfmImage& read = *it->second;
  image->markers = read.markers;
  image->position_prior = read.position_prior;
  if (read.keypoints.size() != image->keypoints.size()) return;
  for (size_t k = 0; k < read.keypoints.size(); ++k) {
    if (!((read.keypoints[k] - image->keypoints[k]).cwiseAbs().maxCoeff() < 1e-3)) return;
  }
  image->scales = read.scales;
}

// The mapper's models written to dir/sparse/0, /1, ... for inspection.
void WriteMappedModels(const std::vector<MappedModel>& models, const fs::path& dir) {
  for (size_t m = 0; m < models.size(); ++m) {
    WriteSparseModel(models[m].reconstruction.ToSparseModel(), dir / "sparse" / std::to_string(m),
                     ModelFormat::kBinary);
  }
}

// Start k: the mapper on `inputs` (random seed + k, none of
// `excluded_pairs` as its initial pair), its largest model handed to the
// refinement in memory, judged; throws NumericalError where either fails or
// the result is ruled out. Adds the pair the model grew from to
// `excluded_pairs`.
CalibrationStart MapAndRefine(const AutoCalibratorOptions& options, const SfmInputs& inputs,
                              const std::string& database_path, int k,
                              const std::optional<double>& markers_focal, bool refine_intrinsics,
                              std::set<image_pair_t>* excluded_pairs, ProgressSink& progress) {
  const fs::path dir =
      k == 0 ? fs::path(options.output_path) : fs::path(options.output_path) / StartDir(k);
  const ModelMappingOptions map =
      MapperOptions(options, options.random_seed + k, refine_intrinsics, *excluded_pairs);
  map.Check();
  SparseModel mapped;
  {
    const std::vector<MappedModel> models = MapModels(inputs, map, progress);
    WriteMappedModels(models, dir);
    excluded_pairs->insert(models.at(0).initial_pair);
    mapped = models.at(0).reconstruction.ToSparseModel();
  }
  CalibrationStart start;
  start.index = k;
  start.num_registered = static_cast<int>(mapped.images.size());
  std::map<std::string, const SfmImage*> by_name;
  for (const auto& [id, image] : inputs.images) by_name[image.name] = &image;
  const ModelRefinementOptions refine = RefinerOptions(options, refine_intrinsics);
  refine.Check();
  ModelSource source;
  source.model_name = (dir / "sparse" / "0").string();
  source.database_name = database_path;
  source.load_model = [&] { return mapped; };
  source.add_extras = [&](SfmImage* image) { AddExtrasFrom(by_name, image); };
  RefinedModel refined = RefineModel(refine, source);
  WriteSparseModel(refined.model, dir / "refined", ModelFormat::kBinary);
  start.refined = std::move(refined.summary);
  start.model = std::move(refined.model);
  if (refine_intrinsics) {
    const size_t num_warnings = start.refined.report.warnings.size();
    JudgeAutoCalibration(markers_focal, &start.refined.report);
    // A focal length poorly determined where the views trade it against
    // the housing: another start cannot cure it either (own fisheye behind
    // a decentred dome: three starts, three identical models).
    if (start.refined.num_geometry_warnings > 0) {
      start.refined.num_geometry_warnings +=
          static_cast<int>(start.refined.report.warnings.size() - num_warnings);
    }
  }
  return start;
}

// Several starts when one cannot be trusted (a wrong basin, or a poorly
// determined solution): another initial pair and the mapper's random
// choices from another seed take another path; the start with the fewest
// warnings, then the smallest residual, is kept (its files moved into the
// output folder). Throws the first start's error when none succeeds.
CalibrationStart BestStart(const AutoCalibratorOptions& options, const SfmInputs& inputs,
                           const std::string& database_path,
                           const std::optional<double>& markers_focal, bool refine_intrinsics,
                           ProgressSink& progress) {
  const int num_starts = refine_intrinsics ? options.max_num_starts : 1;
  std::optional<CalibrationStart> best;
  std::string first_error;
  std::set<image_pair_t> excluded_pairs;
  for (int k = 0; k < num_starts; ++k) {
    try {
      CalibrationStart start = MapAndRefine(options, inputs, database_path, k, markers_focal,
                                            refine_intrinsics, &excluded_pairs, progress);
      if (!best || BetterStart(start, *best)) best = std::move(start);
    } catch (const NumericalError& e) {
      if (first_error.empty()) first_error = e.what();
      LOG(WARNING) << "auto_calibrator: start " << k + 1 << " of " << num_starts
                   << " failed: " << e.what();
    }
    if (best && NumCurableWarnings(best->refined) == 0) break;
    if (k + 1 < num_starts) {
      LOG(WARNING)
          << "auto_calibrator: start " << k + 1
          << " is not to be trusted; mapping again from another initial pair and random seed "
          << options.random_seed + k + 1;
    }
  }
  KeepStart(options.output_path, best ? best->index : -1, num_starts);
  if (!best) throw NumericalError(first_error);
  return std::move(*best);
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
    return BestStart(options, inputs, database_path, markers_focal, refine_intrinsics, progress);
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
