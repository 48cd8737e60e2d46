// How a stage's work is split between the ranks of an MPI job: each rank
// takes one contiguous block of the stage's ordered list (images by name,
// image pairs) and writes its rows into a shard database beside the
// stage's database; rank 0 merges the shards in rank order, so the merged
// ids follow the list's order as a single process's would.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace portcal {

struct Shard {
  int index = 0;
  int count = 1;
  bool Whole() const { return count == 1; }
  void Check() const;  // 0 <= index < count
  // The block [size * index / count, size * (index + 1) / count).
  template <typename T>
  std::vector<T> Block(const std::vector<T>& all) const {
    const size_t begin = all.size() * static_cast<size_t>(index) / static_cast<size_t>(count);
    const size_t end = all.size() * static_cast<size_t>(index + 1) / static_cast<size_t>(count);
    return std::vector<T>(all.begin() + static_cast<std::ptrdiff_t>(begin),
                          all.begin() + static_cast<std::ptrdiff_t>(end));
  }
};

// This rank's shard of the job, over the whole MPI world.
Shard ThisRanksShard();

// DB.shard-I-of-N beside the database.
std::filesystem::path ShardDatabasePath(const std::string& database_path, const Shard& shard);

// Removes a shard database and its journal (nothing to do about one that
// cannot go).
void RemoveShardDatabase(const std::filesystem::path& path);

// Runs `work` on every rank. If it failed on any rank, every rank runs
// `clean_up` and throws: its own error, or one saying another rank failed
// (whose error that rank reports). Every rank must call it together.
void RunOnEveryRank(const std::string& stage, const std::function<void()>& work,
                    const std::function<void()>& clean_up);

}  // namespace portcal
