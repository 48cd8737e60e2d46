#include "colmap_ext/util/progress.h"
#include "pipelines/stages/database_creator.h"
#include "pipelines/stages/pose_prior_importer.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int DatabaseCreatorCommand(int argc, char** argv) {
  DatabaseCreatorOptions options;
  CommandLine cli("database_creator",
                  "Creates a COLMAP 3.8 database (with portcal's tables), or "
                  "checks an existing one.");
  cli.AddRequired("database_path", &options.database_path, "database file to create");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunDatabaseCreator(options, progress);
  });
}

int PosePriorImporterCommand(int argc, char** argv) {
  PosePriorImporterOptions options;
  CommandLine cli("pose_prior_importer",
                  "Stores navigation positions (camera centres, metres, a local Cartesian frame) as the "
                  "images' position priors, from a file of 'NAME X Y Z' lines. The refractive bundle "
                  "adjuster takes the scale from them (--PosePrior.position_sigma).");
  cli.AddRequired("database_path", &options.database_path, "database with the images");
  cli.AddRequired("input_path", &options.input_path, "file of 'NAME X Y Z' lines");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunPosePriorImporter(options, progress);
  });
}

}  // namespace portcal
