// Flag groups several subcommands share, each declared once with one help
// text: one Register per options struct (COLMAP's --Section.option names).
// The fields keep their defaults as the flags' defaults.
#pragma once

#include "pipelines/images/image_reader.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_matcher.h"
#include "pipelines/stages/refractive_bundle_adjuster.h"
#include "pipelines/stages/refractive_mapper.h"
#include "pipelines/stages/target_extractor.h"
#include "tools/command_line.h"

namespace portcal {

// Flags two commands give to fields of their own.
inline constexpr const char* kMarkersDictionaryHelp =
    "ArUco dictionary of the markers, e.g. DICT_4X4_50";
inline constexpr const char* kMaskEnlargementHelp =
    "features kept within each marker's quad scaled by this about its centroid (>= 1)";

// --ImageReader.camera_model, single_camera, single_camera_per_folder,
// camera_params, overwrite.
void Register(CommandLine* cli, ImageReaderOptions* reader);
// --SiftExtraction.*
void Register(CommandLine* cli, SiftExtractionOptions* sift);
// --SiftMatching.*
void Register(CommandLine* cli, DescriptorMatchingOptions* matching);
// --TwoViewGeometry.*
void Register(CommandLine* cli, TwoViewVerificationOptions* verification);
// --SequentialMatching.*
void Register(CommandLine* cli, SequentialPairingOptions* sequential);
// --SpatialMatching.*
void Register(CommandLine* cli, SpatialPairingOptions* spatial);
// --Markers.side_length, side_sigma: ArUco markers as the scale.
void Register(CommandLine* cli, MarkerScale* marker_scale);
// --Mapper.* (with --Markers.side_length, side_sigma, --PosePrior.position_sigma,
// --random_seed and --num_threads of the mapper).
void Register(CommandLine* cli, IncrementalMapperOptions* mapper);
// --Mapper.init_radial_*: the search of the first radial term.
void Register(CommandLine* cli, FocalStartOptions* focal);
void Register(CommandLine* cli, RadialStartOptions* radial);
// --Target.*: the calibration target and how it is detected.
void Register(CommandLine* cli, TargetDetectorOptions* target);
// --BundleAdjustment.* (with --num_threads of the adjustment).
void Register(CommandLine* cli, BundleAdjustmentOptions* ba);

}  // namespace portcal
