#include "pipelines/target_extractor.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int RunTargetExtractor(int argc, char** argv) {
  TargetExtractorOptions options;
  CommandLine cli("target_extractor",
                  "Imports the images into the database (like COLMAP's feature_extractor) and "
                  "stores the chessboard corners found in each (sub-pixel, by fitting the "
                  "ideal corner pattern) in portcal_target_observations, with the per-image "
                  "outcome in portcal_target_detections. One transaction; safe to rerun.");
  cli.AddRequired("database_path", &options.database_path, "database (created if missing)");
  cli.AddRequired("image_path", &options.image_path, "directory of images");
  cli.Add("ImageReader.camera_model", &options.reader.camera_model, "COLMAP camera model");
  cli.Add("ImageReader.single_camera", &options.reader.single_camera, "one camera for all images (0 | 1)");
  cli.Add("ImageReader.camera_params", &options.reader.camera_params,
          "initial parameters in COLMAP's order (default: from the image size)");
  cli.Add("Target.type", &options.target_type, "chessboard");
  cli.Add("Target.cols", &options.chessboard.cols, "inner corners per row");
  cli.Add("Target.rows", &options.chessboard.rows, "inner corners per column");
  cli.Add("Target.square_size", &options.square_size_m, "square side, metres");
  cli.Add("Target.coarse_max_image_size", &options.chessboard.coarse_max_image_size,
          "coarse detection on images downscaled to this size (0: full size)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    ExtractTargets(options, progress);
  });
}

}  // namespace portcal
