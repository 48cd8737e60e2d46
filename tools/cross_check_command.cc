#include <iostream>

#include "colmap_ext/util/progress.h"
#include "pipelines/stages/cross_check.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int CrossCheckCommand(int argc, char** argv) {
  CrossCheckOptions options;
  CommandLine cli("cross_check",
                  "Cross-checks portcal's in-air calibration against mrcal: solves the same "
                  "stored chessboard corners with mrcal's C library (its lens model matching "
                  "the COLMAP model, its board warp, outlier rejection and regularisation), "
                  "compares the parameters against both standard deviations and the "
                  "projections over a grid (mrcal's projection diff: best-fit rotation, then "
                  "pixel differences), names the likely cause of a disagreement and re-runs "
                  "portcal with the board warp to show it. With --CrossCheck.folds K, also "
                  "calibrates K disjoint subsets of the views and compares their differences "
                  "with what the uncertainty predicts. Prints the report; its last line is "
                  "PASS or FAIL (exit code 0 either way).");
  cli.AddRequired("database_path", &options.database_path, "database with target observations");
  cli.AddRequired("input_calibration", &options.input_calibration, "portcal's calibration.yaml");
  cli.AddRequired(
      "output_path", &options.output_path,
      "directory for cross_check.txt/.yaml, report.html, heat maps and .cameramodel files");
  cli.Add("camera_id", &options.camera_id, "camera (-1: the only one with observations)");
  cli.Add("CrossCheck.folds", &options.folds, "cross-validation folds (0: none, else >= 2)");
  cli.Add("CrossCheck.max_diff_px", &options.max_diff_px,
          "PASS threshold on the projection diff's 95th percentile, px");
  cli.Add("CrossCheck.gridn_width", &options.gridn_width, "projection-diff grid points across");
  cli.Add("CrossCheck.mrcal_board_warp", &options.mrcal_board_warp,
          "mrcal fits the board warp (0 | 1)");
  cli.Add("CrossCheck.mrcal_outlier_rejection", &options.mrcal_outlier_rejection,
          "mrcal rejects outlier corners (0 | 1)");
  cli.Add("CrossCheck.mrcal_regularization", &options.mrcal_regularization,
          "mrcal's regularisation terms (0 | 1)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    std::cout << CrossCheckText(RunCrossCheck(options, progress));
  });
}

}  // namespace portcal
