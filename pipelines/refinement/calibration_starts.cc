#include "pipelines/refinement/calibration_starts.h"

#include <map>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/sfm/calibration_start.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// A focal length with a standard deviation above this fraction of itself
// is not determined by the views (well-posed sets: 0.05-0.5 %).
constexpr double kMaxRelativeFocalStdDev = 0.01;

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
CalibrationStart MapAndRefine(const CalibrationStartsOptions& options, const SfmInputs& inputs,
                              int k, const std::optional<double>& markers_focal,
                              std::set<image_pair_t>* excluded_pairs, ProgressSink& progress) {
  const fs::path dir =
      k == 0 ? fs::path(options.output_path) : fs::path(options.output_path) / StartDir(k);
  ModelMappingOptions map = options.map;
  map.mapper.init_excluded_pairs = *excluded_pairs;
  map.mapper.random_seed = options.map.mapper.random_seed + k;
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
  options.refine.Check();
  ModelSource source;
  source.model_name = (dir / "sparse" / "0").string();
  source.database_name = options.database_path;
  source.load_model = [&] { return mapped; };
  source.add_extras = [&](SfmImage* image) {
    const auto read = by_name.find(image->name);
    if (read != by_name.end()) AddExtrasOf(*read->second, image);
  };
  RefinedModel refined = RefineModel(options.refine, source);
  WriteSparseModel(refined.model, dir / "refined", ModelFormat::kBinary);
  start.refined = std::move(refined.summary);
  start.model = std::move(refined.model);
  if (options.refine_intrinsics) {
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

}  // namespace

void JudgeAutoCalibration(const std::optional<double>& markers_focal, CalibrationReport* report) {
  const double focal = report->camera.MeanFocalLength();
  const std::string remedy =
      "give the in-air intrinsics (--ImageReader.camera_params), more views, or views "
      "with wider tilt and nearer the image corners";
  if (markers_focal && !(focal / *markers_focal < kMaxFocalRatioToMarkers &&
                         *markers_focal / focal < kMaxFocalRatioToMarkers)) {
    throw NumericalError(
        "auto_calibrator: the refined focal length " + FormatSignificant(focal, 4) +
        " px is far from the ArUco markers' estimate " + FormatSignificant(*markers_focal, 4) +
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
    report->warnings.push_back(
        "the focal length is poorly determined: std dev " + FormatSignificant(focal_std_dev, 4) +
        " px, " + FormatSignificant(100 * focal_std_dev / focal, 4) + " % of it; " + remedy);
    LOG(WARNING) << "auto_calibrator: " << report->warnings.back();
  }
}

CalibrationStart BestStart(const CalibrationStartsOptions& options, const SfmInputs& inputs,
                           const std::optional<double>& markers_focal, ProgressSink& progress) {
  const int num_starts = options.refine_intrinsics ? options.max_num_starts : 1;
  std::optional<CalibrationStart> best;
  std::string first_error;
  std::set<image_pair_t> excluded_pairs;
  for (int k = 0; k < num_starts; ++k) {
    try {
      CalibrationStart start =
          MapAndRefine(options, inputs, k, markers_focal, &excluded_pairs, progress);
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
          << options.map.mapper.random_seed + k + 1;
    }
  }
  KeepStart(options.output_path, best ? best->index : -1, num_starts);
  if (!best) throw NumericalError(first_error);
  return std::move(*best);
}

}  // namespace portcal
