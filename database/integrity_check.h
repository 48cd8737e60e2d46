// A database that a stage will copy whole (database_converter, and
// database_merger's inputs) is checked first: VACUUM INTO and the merge
// read every page, and a damaged page or a row that refers to a missing one
// would otherwise be copied into a file that looks sound (SQLite reports
// many damaged pages only where a query happens to read them).
#pragma once

#include <filesystem>

namespace portcal {

// Runs PRAGMA quick_check (every page's structure; O(file size), about a
// second per GiB) and PRAGMA foreign_key_check (rows that refer to a camera
// or image the file does not hold). Throws InputError naming the file and
// the first problems found; reads only.
void CheckDatabaseIntegrity(const std::filesystem::path& path);

}  // namespace portcal
