#pragma once

#include <filesystem>

namespace portcal {

// Creates a COLMAP 3.8 database with portcal's tables at `path`, or checks an
// existing one (as `colmap database_creator` does). Throws DatabaseError.
void CreateDatabase(const std::filesystem::path& path);

}  // namespace portcal
