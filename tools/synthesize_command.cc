#include "pipelines/stages/synthesize.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int SynthesizeCommand(int argc, char** argv) {
  SynthesizeOptions options;
  CommandLine cli("synthesize",
                  "Renders a calibration image set with exact ground truth: DIR/images/*.png "
                  "and DIR/ground_truth.yaml (the format of ../shared/datasets/rendered). The "
                  "config is the YAML of those sets' config_used.yaml, plus stereo, aruco_grid, "
                  "charuco, target3d, survey, water, vignetting, motion_blur and occlusion "
                  "(see docs/synthesize.md).");
  cli.AddRequired("config", &options.config_path, "dataset YAML");
  cli.AddRequired("output_path", &options.output_path, "output directory");
  cli.Add("seed", &options.seed, "overrides the config's seed when >= 0");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunSynthesize(options, progress);
  });
}

}  // namespace portcal
