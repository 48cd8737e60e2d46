#include "pipelines/database_creator.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int RunDatabaseCreator(int argc, char** argv) {
  std::string database_path;
  CommandLine cli("database_creator",
                  "Creates a COLMAP 3.8 database (with portcal's tables), or "
                  "checks an existing one.");
  cli.AddRequired("database_path", &database_path, "database file to create");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    CreateDatabase(database_path);
  });
}

}  // namespace portcal
