#include "colmap_ext/util/progress.h"
#include "pipelines/stages/database_converter.h"
#include "pipelines/stages/database_creator.h"
#include "pipelines/stages/database_merger.h"
#include "pipelines/stages/pose_prior_importer.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int DatabaseCreatorCommand(int argc, char** argv) {
  DatabaseCreatorOptions options;
  CommandLine cli(
      "database_creator",
      "Creates a COLMAP database (with portcal's tables) of the layout of COLMAP 3.8 (Debian 12's, "
      "the default) to 4.1, or checks an existing one.");
  cli.AddRequired("database_path", &options.database_path, "database file to create");
  std::vector<std::pair<std::string, std::optional<ColmapVersion>>> versions = {
      {"auto", std::nullopt}};
  for (const auto& [name, version] : ColmapVersionChoices()) versions.emplace_back(name, version);
  cli.AddChoice(
      "Database.colmap_version", &options.colmap_version, versions,
      "the layout of a new database (auto: 3.8), or the one an existing database must have");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunDatabaseCreator(options, progress);
  });
}

int DatabaseConverterCommand(int argc, char** argv) {
  DatabaseConverterOptions options;
  CommandLine cli(
      "database_converter",
      "Converts a database to the layout of another COLMAP version (3.8 to 4.1, up or down) as "
      "that "
      "version's migration does, keeping every row: pose priors between images.prior_* and "
      "pose_priors, one rig per camera and one frame per image, the descriptors' type, NULL for "
      "unset two-view geometry. Refuses, changing nothing, what the target cannot hold (a rig of "
      "several cameras or ALIKED descriptors in 3.x). In place, or into --output_path.");
  cli.AddRequired("database_path", &options.database_path, "database to convert");
  cli.Add("output_path", &options.output_path,
          "write the converted copy here instead (a new file)");
  cli.AddChoice("Database.colmap_version", &options.colmap_version, ColmapVersionChoices(),
                "the COLMAP version whose layout to convert to");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunDatabaseConverter(options, progress);
  });
}

int DatabaseMergerCommand(int argc, char** argv) {
  DatabaseMergerOptions options;
  CommandLine cli(
      "database_merger",
      "Merges two databases into a new one, as COLMAP's database_merger: the first's rows, then "
      "the "
      "second's cameras and images with new ids and every row about them (features, matches, "
      "geometries, pose priors, portcal's tables), in the first's COLMAP layout. An image name in "
      "both is an error.");
  cli.AddRequired("database_path1", &options.database_path1, "first database");
  cli.AddRequired("database_path2", &options.database_path2, "second database");
  cli.AddRequired("merged_database_path", &options.merged_database_path,
                  "the merged database (a new file)");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunDatabaseMerger(options, progress);
  });
}

int PosePriorImporterCommand(int argc, char** argv) {
  PosePriorImporterOptions options;
  CommandLine cli(
      "pose_prior_importer",
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
