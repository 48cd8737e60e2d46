// Records a stage run in portcal_stage_log, inside the stage's transaction.
#pragma once

#include <chrono>
#include <map>
#include <string>

#include "database/database.h"

namespace portcal {

std::string CurrentTimeIso8601();

class StageRun {
 public:
  // `options` as "name=value" lines, shown in the log.
  StageRun(std::string stage, std::string options);
  // Writes the completed-run row; call just before committing.
  void Finish(Database* database, const std::map<std::string, int64_t>& counts);

 private:
  std::string stage_;
  std::string options_;
  std::string start_time_;
};

}  // namespace portcal
