// `portcal refractive_mapper`: incremental structure-from-motion on the
// database's verified matches, every observation a ray in water when the
// camera has a housing (portcal_housings, or --Housing.* for all cameras).
// When a camera has no prior focal length and ArUco markers were detected
// (feature_masker), the markers pre-calibrate its focal length. Writes one
// COLMAP sparse model per reconstructed component into output_path/0, /1,
// ... (binary, plus housings.txt), largest first.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/sfm/incremental_mapper.h"
#include "pipelines/sfm/radial_start.h"

namespace portcal {

struct HousingOverride {
  std::string model;   // "" = the database's housings
  std::string params;  // comma or space separated, the model's order
};

struct RefractiveMapperOptions {
  std::string database_path;
  std::string image_path;  // accepted for COLMAP compatibility
  std::string output_path;
  IncrementalMapperOptions mapper;
  HousingOverride housing;
  // -1: when the camera has no prior focal length; 0: never; 1: always.
  int init_focal_from_markers = -1;
  // The lens's first radial term from the verified matches (radial_start.h)
  // before mapping. -1: when the camera has no prior focal length, its
  // distortion is all zero, the mapper refines it and the model is not a
  // fisheye; 0: never; 1: always.
  int init_radial_from_matches = -1;
  RadialStartOptions radial_start;
  void Check() const;  // throws OptionError naming the option
};

struct RefractiveMapperSummary {
  int num_models = 0;
  int num_registered = 0;  // over all models
  int num_images = 0;
  std::vector<std::filesystem::path> model_paths;
  // Per model: its global adjustments that refined the intrinsics or housing.
  std::vector<std::vector<CalibrationRefinement>> calibration_refinements;
};

// Sets the housing of every camera when `override.model` is given.
void ApplyHousingOverride(const HousingOverride& override_housing, std::map<camera_t, HousedCamera>* cameras);

// A focal length this far from the markers' estimate (measured within
// 1-6 % of the truth on own and shared renders) is a wrong solution,
// whatever its standard deviation says.
constexpr double kMaxFocalRatioToMarkers = 1.25;

// Focal lengths from the markers of each camera's images (see
// FocalLengthFromMarkers), where `mode` asks for it. True if any was set.
bool InitializeFocalFromMarkers(const SfmInputs& inputs, int mode, std::map<camera_t, HousedCamera>* cameras);

// The first radial term of each camera from the matches
// (EstimateFirstRadialTerm), where `options.init_radial_from_matches` asks.
void InitializeRadialFromMatches(const SfmInputs& inputs, const RefractiveMapperOptions& options,
                                 std::map<camera_t, HousedCamera>* cameras);

RefractiveMapperSummary RunRefractiveMapper(const RefractiveMapperOptions& options, ProgressSink& progress);

}  // namespace portcal
