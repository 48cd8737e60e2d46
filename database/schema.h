#pragma once

#include <string>
#include <vector>

namespace portcal {

// CREATE statements of COLMAP 3.8's tables, in COLMAP's order.
const std::vector<std::string>& ColmapSchemaSql();
// CREATE statements of portcal's own tables (all prefixed portcal_).
const std::vector<std::string>& PortcalSchemaSql();

}  // namespace portcal
