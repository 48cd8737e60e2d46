#include "database/stage_run.h"

#include <ctime>

namespace portcal {

std::string CurrentTimeIso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buffer;
}

StageRun::StageRun(std::string stage, std::string options)
    : stage_(std::move(stage)), options_(std::move(options)), start_time_(CurrentTimeIso8601()) {}

void StageRun::Finish(Database* database, const std::map<std::string, int64_t>& counts) {
  StageLogEntry entry;
  entry.stage = stage_;
  entry.options = options_;
  entry.start_time = start_time_;
  entry.end_time = CurrentTimeIso8601();
  entry.status = "succeeded";
  for (const auto& [name, value] : counts) {
    entry.counts += name + "=" + std::to_string(value) + "\n";
  }
  database->WriteStageLog(entry);
}

}  // namespace portcal
