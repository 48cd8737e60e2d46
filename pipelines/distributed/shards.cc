#include "pipelines/distributed/shards.h"

#include <exception>
#include <system_error>

#include "colmap_ext/util/error.h"
#include "pipelines/distributed/mpi_world.h"

namespace portcal {

void Shard::Check() const {
  if (count < 1 || index < 0 || index >= count) {
    throw InputError("shard " + std::to_string(index) + " of " + std::to_string(count) +
                     ": not a shard");
  }
}

Shard ThisRanksShard() { return Shard{MpiWorld::Rank(), MpiWorld::Size()}; }

std::filesystem::path ShardDatabasePath(const std::string& database_path, const Shard& shard) {
  return database_path + ".shard-" + std::to_string(shard.index) + "-of-" +
         std::to_string(shard.count);
}

void RemoveShardDatabase(const std::filesystem::path& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  std::filesystem::remove(path.string() + "-journal", ignored);
}

void RunOnEveryRank(const std::string& stage, const std::function<void()>& work,
                    const std::function<void()>& clean_up) {
  std::exception_ptr error;
  try {
    work();
  } catch (...) {
    error = std::current_exception();
  }
  if (MpiWorld::AllSucceeded(error == nullptr)) return;
  clean_up();
  if (error) std::rethrow_exception(error);
  throw std::runtime_error(stage +
                           ": another rank of the MPI job failed (its error is above); rank " +
                           std::to_string(MpiWorld::Rank()) + " stopped too, nothing was written");
}

}  // namespace portcal
