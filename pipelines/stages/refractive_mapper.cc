#include "pipelines/stages/refractive_mapper.h"

#include <algorithm>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace fs = std::filesystem;

namespace portcal {

void RefractiveMapperOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a directory for the models");
  if (init_focal_from_markers < -1 || init_focal_from_markers > 1) {
    throw OptionError("--Mapper.init_focal_from_markers", std::to_string(init_focal_from_markers), "-1, 0 or 1");
  }
  if (init_radial_from_matches < -1 || init_radial_from_matches > 1) {
    throw OptionError("--Mapper.init_radial_from_matches", std::to_string(init_radial_from_matches), "-1, 0 or 1");
  }
  radial_start.Check();
  if (housing.model.empty() != housing.params.empty()) {
    throw OptionError("--Housing.params", housing.params, "given together with --Housing.model");
  }
  mapper.Check();
}

void ApplyHousingOverride(const HousingOverride& override_housing, std::map<camera_t, HousedCamera>* cameras) {
  if (override_housing.model.empty()) return;
  std::vector<double> params;
  for (const std::string& token : SplitTokens(override_housing.params, ", ")) {
    try {
      params.push_back(std::stod(token));
    } catch (const std::exception&) {
      throw OptionError("--Housing.params", override_housing.params, "numbers");
    }
  }
  const Housing housing = Housing::FromName(override_housing.model, params, "--Housing.params");
  for (auto& [id, camera] : *cameras) camera.housing = housing;
}

bool InitializeFocalFromMarkers(const SfmInputs& inputs, int mode, std::map<camera_t, HousedCamera>* cameras) {
  if (mode == 0) return false;
  bool any = false;
  for (auto& [camera_id, camera] : *cameras) {
    if (mode == -1 && camera.camera.has_prior_focal_length) continue;
    std::vector<MarkerQuad> quads;
    for (const auto& [image_id, image] : inputs.images) {
      if (image.camera_id != camera_id) continue;
      for (const MarkerDetection& m : image.markers) quads.push_back({m.corners});
    }
    auto focal = FocalLengthFromMarkers(quads, camera.camera.PrincipalPointX(), camera.camera.PrincipalPointY());
    // The markers give the focal length the camera appears to have in
    // water (a flat port magnifies paraxial rays); bundle adjustment refines
    // the rest.
    if (focal && camera.housing) *focal *= camera.housing->InAirFocalRatio();
    if (!focal) {
      LOG(WARNING) << "camera " << camera_id << ": too few markers for a focal length; keeping "
                   << camera.camera.MeanFocalLength() << " px";
      continue;
    }
    LOG(INFO) << "camera " << camera_id << ": focal length from " << quads.size() << " markers: " << *focal
              << " px (was " << camera.camera.MeanFocalLength() << ")";
    for (int idx : CameraModelFocalLengthIdxs(camera.camera.model_id)) camera.camera.params[idx] = *focal;
    any = true;
  }
  return any;
}

void InitializeRadialFromMatches(const SfmInputs& inputs, const RefractiveMapperOptions& options,
                                 std::map<camera_t, HousedCamera>* cameras) {
  const int mode = options.init_radial_from_matches;
  if (mode == 0 || (mode == -1 && !options.mapper.ba_refine_extra_params)) return;
  for (auto& [camera_id, camera] : *cameras) {
    const std::vector<int> extra = CameraModelExtraParamsIdxs(camera.camera.model_id);
    const bool undistorted = std::all_of(extra.begin(), extra.end(),
                                         [&](int idx) { return camera.camera.params[idx] == 0; });
    // A fisheye model at k = 0 is the equidistant projection, near what
    // fisheye lenses are built to, where k = 0 of a pinhole model is far
    // from a wide angle's; and for a fisheye a focal length error is not
    // projective, so the search takes it up (docs/auto_calibration.md).
    const bool fisheye = CameraModelIsFisheye(camera.camera.model_id);
    if (mode == -1 && (camera.camera.has_prior_focal_length || !undistorted || fisheye)) continue;
    const auto start = EstimateFirstRadialTerm(inputs, camera_id, camera, options.radial_start);
    if (!start) {
      VLOG(1) << "camera " << camera_id << ": no first radial term from the matches (no such term or too few pairs)";
      continue;
    }
    LOG(INFO) << "camera " << camera_id << ": first radial term from " << start->num_matches << " matches of "
              << start->num_pairs << " pairs: " << start->k << " (epipolar RMS " << start->residual_px
              << " px; at the start " << start->residual_at_start_px << " px)";
    camera.camera.params[FirstRadialParamIdx(camera.camera)] = start->k;
  }
}

RefractiveMapperSummary RunRefractiveMapper(const RefractiveMapperOptions& options, ProgressSink& progress) {
  options.Check();
  SfmInputs inputs;
  {
    Database database(options.database_path, Database::OpenMode::kReadOnly);
    inputs = SfmInputs::Read(&database);
  }
  if (inputs.pair_inliers.empty()) {
    throw InputError(options.database_path + ": no verified image pairs; run a matcher first");
  }
  if (options.mapper.position_prior_sigma_m > 0 &&
      std::none_of(inputs.images.begin(), inputs.images.end(),
                   [](const auto& entry) { return entry.second.position_prior.has_value(); })) {
    throw InputError(options.database_path + ": no image has a position prior, so --PosePrior.position_sigma "
                     "has nothing to use (run pose_prior_importer, or set it to 0)");
  }
  std::map<camera_t, HousedCamera> cameras = inputs.cameras;
  ApplyHousingOverride(options.housing, &cameras);
  IncrementalMapperOptions mapper = options.mapper;
  if (InitializeFocalFromMarkers(inputs, options.init_focal_from_markers, &cameras)) {
    mapper.max_focal_ratio_to_start = std::min(mapper.max_focal_ratio_to_start, kMaxFocalRatioToMarkers);
  }
  InitializeRadialFromMatches(inputs, options, &cameras);
  const std::vector<MappedModel> models = RunIncrementalMapper(inputs, cameras, mapper, progress);
  if (models.empty()) {
    throw NumericalError("refractive_mapper: no model could be initialised from " +
                         std::to_string(inputs.pair_inliers.size()) +
                         " verified pairs (too few inlier matches or too little parallax; see "
                         "--Mapper.init_min_num_inliers and --Mapper.init_min_tri_angle)");
  }
  RefractiveMapperSummary summary;
  summary.num_images = static_cast<int>(inputs.images.size());
  for (size_t m = 0; m < models.size(); ++m) {
    const fs::path dir = fs::path(options.output_path) / std::to_string(m);
    WriteSparseModel(models[m].reconstruction.ToSparseModel(), dir, ModelFormat::kBinary);
    summary.model_paths.push_back(dir);
    summary.num_registered += static_cast<int>(models[m].reconstruction.poses().size());
    const auto& refinements = models[m].calibration_refinements;
    const auto held = std::find_if(refinements.begin(), refinements.end(),
                                   [](const CalibrationRefinement& c) { return c.settled; });
    summary.calibration_refinements.push_back(refinements);
    if (held != refinements.end()) {
      LOG(INFO) << "refractive_mapper: model " << m << ": intrinsics and housing held from " << held->num_images
                << " images on (that refinement moved the image by " << held->image_shift_px
                << " px), refined again at the end";
    }
  }
  summary.num_models = static_cast<int>(models.size());
  LOG(INFO) << "refractive_mapper: " << summary.num_models << " model(s), " << summary.num_registered << " of "
            << summary.num_images << " images registered; written to " << options.output_path;
  return summary;
}

}  // namespace portcal
