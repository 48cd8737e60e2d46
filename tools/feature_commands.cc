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
  Register(&cli, &options.reader);
  Register(&cli, &options.sift);
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
  cli.Add("Markers.dictionary", &options.dictionary, kMarkersDictionaryHelp);
  cli.Add("Mask.enlargement_factor", &options.enlargement_factor, kMaskEnlargementHelp);
  cli.Add("Mask.keep_all_features", &options.keep_all_features,
          "1: store the markers and keep every feature (a survey whose markers give the scale)");
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
  Register(cli, &options->matching);
  Register(cli, &options->verification);
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
  Register(&cli, &options.sequential);
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
  Register(&cli, &options.spatial);
  return ParseAndMatch(&cli, options, argc, argv);
}

}  // namespace portcal
