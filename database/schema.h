#pragma once

#include <string>
#include <vector>

#include "database/colmap_layout.h"

namespace portcal {

// CREATE statements of `version`'s tables, in the order and the very text
// COLMAP runs them (colmap_schemas.cc).
const std::vector<std::string>& ColmapSchemaSql(ColmapVersion version);
// CREATE statements of portcal's own tables (all prefixed portcal_).
const std::vector<std::string>& PortcalSchemaSql();

}  // namespace portcal
