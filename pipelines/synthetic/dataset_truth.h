// What a synthetic set says of itself beside its images: the ground
// truth's header (names, cameras, housings, rig), what ground_truth.yaml
// records beyond cameras and poses (clutter, image formation, occlusion, the
// survey or the pose sampling), and a survey's noisy navigation.
#pragma once

#include <cstdint>
#include <string>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/synthetic/dataset_config.h"
#include "pipelines/synthetic/dataset_scene.h"

namespace portcal {

// The set's ground truth before any frame; `dir1`, `dir2`: the cameras'
// image folders (relative to the set).
GroundTruth DatasetTruthHeader(const DatasetConfig& config, const std::string& dir1,
                               const std::string& dir2);

// The YAML ground_truth.yaml appends after the cameras and frames: how the
// scene and the images were made, so a reader can reproduce them.
std::string DatasetExtraYaml(const DatasetConfig& config, const Scene& scene);

// A survey's navigation: each image's camera centre plus Gaussian noise of
// `sigma_m` per axis (seeded by `seed`), as pose_prior_importer reads it
// (names relative to images/).
std::string NavigationText(const GroundTruth& truth, double sigma_m, uint64_t seed);

}  // namespace portcal
