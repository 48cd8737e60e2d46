// Subcommands of the auto-calibration front end: feature_extractor,
// feature_masker, exhaustive_matcher, sequential_matcher.
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_masker.h"
#include "pipelines/stages/feature_matcher.h"
#include "tools/command_line.h"
#include "tools/commands.h"
#include "tools/option_groups.h"

namespace portcal {

int FeatureExtractorCommand(int argc, char** argv) {
  FeatureExtractorOptions options;
  CommandLine cli("feature_extractor",
                  "Imports the images into the database (like COLMAP's ImageReader) and stores "
                  "SIFT keypoints and descriptors exactly as COLMAP does (6-column affine "
                  "keypoints, RootSIFT uint8 descriptors), so COLMAP's matchers and mapper can "
                  "use them. Images with features are skipped unless --overwrite 1.");
  cli.AddRequired("database_path", &options.database_path, "database (created if missing)");
  cli.AddRequired("image_path", &options.image_path, "directory of images");
  AddImageReaderOptions(&cli, &options.reader);
  cli.Add("SiftExtraction.max_num_features", &options.sift.max_num_features, "strongest features kept");
  cli.Add("SiftExtraction.max_image_size", &options.sift.max_image_size, "larger images are downscaled");
  cli.Add("SiftExtraction.first_octave", &options.sift.first_octave, "-1: start at 2x upsampled");
  cli.Add("SiftExtraction.octave_resolution", &options.sift.octave_resolution, "scales per octave");
  cli.Add("SiftExtraction.peak_threshold", &options.sift.peak_threshold, "DoG peak threshold (COLMAP's units)");
  cli.Add("SiftExtraction.edge_threshold", &options.sift.edge_threshold, "edge response threshold");
  cli.Add("overwrite", &options.overwrite, "re-extract images that have features (0 | 1)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunFeatureExtractor(options, progress);
  });
}

int FeatureMaskerCommand(int argc, char** argv) {
  FeatureMaskerOptions options;
  CommandLine cli("feature_masker",
                  "Detects ArUco markers and keeps only the features inside each marker's quad "
                  "scaled about its centroid by --Mask.enlargement_factor; stores the markers. "
                  "Matches of changed images are deleted. One transaction; safe to rerun.");
  cli.AddRequired("database_path", &options.database_path, "database with features");
  cli.AddRequired("image_path", &options.image_path, "directory of the images");
  cli.Add("Mask.dictionary", &options.dictionary, "ArUco dictionary, e.g. DICT_4X4_50");
  cli.Add("Mask.enlargement_factor", &options.enlargement_factor, "quad scale about its centroid (>= 1)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunFeatureMasker(options, progress);
  });
}

namespace {

void AddMatchingOptions(CommandLine* cli, FeatureMatcherOptions* options) {
  cli->AddRequired("database_path", &options->database_path, "database with features");
  cli->Add("SiftMatching.max_ratio", &options->matching.max_ratio, "Lowe's ratio test");
  cli->Add("SiftMatching.max_distance", &options->matching.max_distance, "max descriptor angle, radians");
  cli->Add("SiftMatching.cross_check", &options->matching.cross_check, "mutual matches only (0 | 1)");
  cli->Add("SiftMatching.max_num_matches", &options->matching.max_num_matches, "per pair");
  cli->Add("SiftMatching.method", &options->matching.method,
           "brute_force (exact) | kdtree (approximate, FLANN)");
  cli->Add("SiftMatching.kdtree_num_trees", &options->matching.kdtree_num_trees, "randomized k-d trees");
  cli->Add("SiftMatching.kdtree_num_checks", &options->matching.kdtree_num_checks, "leaves visited per query");
  cli->Add("TwoViewGeometry.max_error", &options->verification.max_error, "RANSAC threshold, pixels");
  cli->Add("TwoViewGeometry.confidence", &options->verification.confidence, "RANSAC confidence");
  cli->Add("TwoViewGeometry.max_num_trials", &options->verification.max_num_trials, "RANSAC iterations");
  cli->Add("TwoViewGeometry.min_num_inliers", &options->verification.min_num_inliers, "per verified pair");
  cli->Add("TwoViewGeometry.min_inlier_ratio", &options->verification.min_inlier_ratio,
           "inliers / matches for a verified pair");
  cli->Add("random_seed", &options->verification.random_seed,
           "seed of E's and H's RANSAC samples (>= 0): same matches, same geometry");
  cli->Add("overwrite", &options->overwrite, "re-match pairs that have a geometry (0 | 1)");
  cli->Add("num_threads", &options->num_threads, "threads");
}

int ParseAndMatch(CommandLine* cli, const FeatureMatcherOptions& options, int argc, char** argv) {
  return ReportErrors([&] {
    if (!cli->Parse(argc, argv)) return;
    StderrProgress progress;
    RunFeatureMatcher(options, progress);
  });
}

}  // namespace

int ExhaustiveMatcherCommand(int argc, char** argv) {
  FeatureMatcherOptions options;
  options.mode = PairingMode::kExhaustive;
  CommandLine cli("exhaustive_matcher",
                  "Matches every image pair (nearest neighbours, ratio and cross check) and "
                  "verifies each geometrically (E, F, H by RANSAC, COLMAP's configurations). "
                  "Pairs already verified are skipped; safe to rerun.");
  AddMatchingOptions(&cli, &options);
  return ParseAndMatch(&cli, options, argc, argv);
}

int SequentialMatcherCommand(int argc, char** argv) {
  FeatureMatcherOptions options;
  options.mode = PairingMode::kSequential;
  CommandLine cli("sequential_matcher",
                  "Matches each image with the next --SequentialMatching.overlap images in name "
                  "order (and, with loop_detection, with its most similar images by a visual-word "
                  "index), then verifies each pair geometrically. Safe to rerun.");
  AddMatchingOptions(&cli, &options);
  cli.Add("SequentialMatching.overlap", &options.sequential.overlap, "next images matched");
  cli.Add("SequentialMatching.quadratic_overlap", &options.sequential.quadratic_overlap,
          "also the images 2^k ahead (0 | 1)");
  cli.Add("SequentialMatching.loop_detection", &options.sequential.loop_detection,
          "loop candidates by image retrieval (0 | 1)");
  cli.Add("SequentialMatching.loop_detection_period", &options.sequential.loop_detection_period,
          "every n-th image queries the index");
  cli.Add("SequentialMatching.loop_detection_num_images", &options.sequential.loop_detection_num_images,
          "most similar images matched per query");
  cli.Add("SequentialMatching.vocabulary_size", &options.sequential.vocabulary_size, "visual words");
  return ParseAndMatch(&cli, options, argc, argv);
}

int SpatialMatcherCommand(int argc, char** argv) {
  FeatureMatcherOptions options;
  options.mode = PairingMode::kSpatial;
  CommandLine cli("spatial_matcher",
                  "Matches each image with its nearest images by position prior (navigation; "
                  "pose_prior_importer), as COLMAP's spatial_matcher, then verifies each pair "
                  "geometrically. Safe to rerun.");
  AddMatchingOptions(&cli, &options);
  cli.Add("SpatialMatching.max_num_neighbors", &options.spatial.max_num_neighbors, "nearest images matched");
  cli.Add("SpatialMatching.max_distance", &options.spatial.max_distance_m, "metres between positions");
  cli.Add("SpatialMatching.ignore_z", &options.spatial.ignore_z, "horizontal distances only (0 | 1)");
  return ParseAndMatch(&cli, options, argc, argv);
}

}  // namespace portcal
