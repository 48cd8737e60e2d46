// The portcal executable: a table of colmap-style subcommands.
#include <algorithm>
#include <csignal>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/memory.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/distributed/mpi_world.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const std::vector<Command>& Commands() {
  static const std::vector<Command> kCommands = {
      {"database_creator", portcal::DatabaseCreatorCommand,
       "create a COLMAP database (the layout of 3.8, default, to 4.1) with portcal's tables"},
      {"database_converter", portcal::DatabaseConverterCommand,
       "convert a database between COLMAP versions' layouts (3.8 to 4.1), keeping every row"},
      {"database_merger", portcal::DatabaseMergerCommand,
       "merge two databases into a new one (ids remapped, portcal's tables included)"},
      {"pose_prior_importer", portcal::PosePriorImporterCommand,
       "store navigation positions as the images' position priors"},
      {"model_converter", portcal::ModelConverterCommand,
       "convert sparse models between BIN and TXT (and import the refractive "
       "fork's cameras.txt)"},
      {"image_undistorter", portcal::ImageUndistorterCommand,
       "pinhole images and model (a COLMAP dense workspace) from a refractive or distorted camera"},
      {"project_points", portcal::ProjectPointsCommand,
       "project 3-D points through a camera and housing (or unproject pixels "
       "to rays)"},
      {"target_extractor", portcal::TargetExtractorCommand,
       "import images and store the calibration target's corners seen in each"},
      {"camera_calibrator", portcal::CameraCalibratorCommand,
       "calibrate camera intrinsics from the stored target observations"},
      {"housing_calibrator", portcal::HousingCalibratorCommand,
       "calibrate a flat or dome port, the in-air intrinsics given"},
      {"stereo_calibrator", portcal::StereoCalibratorCommand,
       "calibrate a stereo rig's relative pose, in air or behind housings"},
      {"calibration_evaluator", portcal::CalibrationEvaluatorCommand,
       "judge a calibration on held-out views (pose alone per view), K-fold cross-validation"},
      {"feature_extractor", portcal::FeatureExtractorCommand,
       "import images and store SIFT features as COLMAP does"},
      {"feature_masker", portcal::FeatureMaskerCommand,
       "keep only the features near ArUco markers"},
      {"exhaustive_matcher", portcal::ExhaustiveMatcherCommand,
       "match and verify every image pair"},
      {"sequential_matcher", portcal::SequentialMatcherCommand,
       "match and verify neighbouring images (and loop candidates)"},
      {"spatial_matcher", portcal::SpatialMatcherCommand,
       "match and verify images near each other by position prior"},
      {"refractive_mapper", portcal::RefractiveMapperCommand,
       "incremental structure-from-motion on refracted rays"},
      {"hierarchical_mapper", portcal::HierarchicalMapperCommand,
       "refractive mapping of a large survey in overlapping clusters (on MPI ranks), merged"},
      {"refractive_bundle_adjuster", portcal::RefractiveBundleAdjusterCommand,
       "bundle adjustment that self-calibrates the housing (and intrinsics)"},
      {"calibration_subset_selector", portcal::CalibrationSubsetSelectorCommand,
       "the images of a survey to self-calibrate the housing on (an image list for the mapper)"},
      {"auto_calibrator", portcal::AutoCalibratorCommand,
       "calibrate from ArUco-marked objects without a known target: all stages"},
      {"cross_check", portcal::CrossCheckCommand,
       "cross-check an in-air calibration with mrcal, and cross-validate it"},
      {"live_calibrator", portcal::LiveCalibratorCommand,
       "calibrate from a camera, video file or stream: hands-free capture, next-pose guidance"},
      {"pose_suggester", portcal::PoseSuggesterCommand,
       "the next target poses to hold, from the views so far (planning a dive)"},
      {"synthesize", portcal::SynthesizeCommand,
       "render a calibration image set (targets, stereo, surveys, underwater "
       "effects) with exact ground truth"},
  };
  return kCommands;
}

void PrintHelp() {
  std::cout
      << "portcal " << PORTCAL_VERSION
      << " -- camera, stereo and housing calibration for underwater "
         "photogrammetry\n\nUsage:\n  portcal <command> [options]\n"
         "  portcal <command> -h [GROUP]    the command's options (with GROUP: only --GROUP.*)\n"
         "  portcal help <command> [GROUP]  the same\n\nCommands:\n";
  // The summaries start two spaces after the longest name.
  size_t width = std::string("help").size();
  for (const Command& command : Commands())
    width = std::max(width, std::string(command.name).size());
  const auto print = [width](const std::string& name, const std::string& summary) {
    std::cout << "  " << name << std::string(width + 2 - name.size(), ' ') << summary << "\n";
  };
  print("help", "list the commands");
  for (const Command& command : Commands()) print(command.name, command.summary);
}

void HandleSignal(int signal) {
  // First signal: ask the running stage to stop (it rolls back); second:
  // default action.
  portcal::CancelFlag::Request();
  std::signal(signal, SIG_DFL);
}

}  // namespace

namespace {

// "; did you mean camera_calibrator?" for a command a few typing errors
// away or that the word begins (as options get), else "".
std::string DidYouMean(const std::string& word) {
  std::vector<std::pair<size_t, std::string>> ranked;
  for (const Command& command : Commands()) {
    const std::string name = command.name;
    const size_t distance =
        name.rfind(word, 0) == 0 && word.size() >= 3 ? 0 : portcal::EditDistance(word, name);
    if (distance <= std::max<size_t>(2, word.size() / 4)) ranked.emplace_back(distance, name);
  }
  std::sort(ranked.begin(), ranked.end());
  std::string text;
  for (size_t k = 0; k < ranked.size() && k < 3; ++k)
    text += (k ? ", " : "; did you mean ") + ranked[k].second;
  return text.empty() ? text : text + "?";
}

int RunCommandLine(int argc, char** argv) {
  portcal::InitializeLogging(argv[0]);
  portcal::KeepImageBuffersInTheHeap();
  if (argc >= 3 && std::strcmp(argv[1], "help") == 0) {
    // "portcal help CMD [GROUP]" is "portcal CMD -h [GROUP]".
    for (const Command& command : Commands()) {
      if (command.name != std::string(argv[2])) continue;
      std::vector<char*> args = {argv[2], const_cast<char*>("-h")};
      if (argc >= 4) args.push_back(argv[3]);
      return command.run(static_cast<int>(args.size()), args.data());
    }
    std::cerr << "error: unknown command '" << argv[2] << "'" << DidYouMean(argv[2])
              << " (portcal help lists the commands)\n";
    return portcal::kExitUsage;
  }
  if (argc < 2 || std::strcmp(argv[1], "help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "--help") == 0) {
    PrintHelp();
    return argc < 2 ? portcal::kExitUsage : portcal::kExitSuccess;
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "version") == 0) {
    std::cout << "portcal " << PORTCAL_VERSION << "\n";
    return portcal::kExitSuccess;
  }
  for (const Command& command : Commands()) {
    if (command.name == std::string(argv[1])) {
      return command.run(argc - 1, argv + 1);
    }
  }
  std::cerr << "error: unknown command '" << argv[1] << "'" << DidYouMean(argv[1])
            << " (portcal help lists the commands)\n";
  return portcal::kExitUsage;
}

}  // namespace

// Under mpirun or srun every rank runs the same command line (the stages
// split their work: pipelines/distributed/).
int main(int argc, char** argv) {
  // First: MPI's start-up takes a fifth of a second, and a stop asked for
  // in it must not be lost (a signal ignored, or the default that leaves
  // no message).
  std::signal(SIGINT, HandleSignal);
  std::signal(SIGTERM, HandleSignal);
  portcal::MpiWorld::Init(&argc, &argv);
  const int code = RunCommandLine(argc, argv);
  portcal::MpiWorld::Finalize();
  return code;
}
