#include "database/colmap_layout.h"

#include <algorithm>

#include "colmap_ext/util/error.h"
#include "database/statement.h"

namespace portcal {
namespace {

// The newest user_version portcal knows: COLMAP 4.1.x (4.1.99, any schema
// revision). A later minor version may change the tables.
constexpr int64_t kNewestKnownUserVersion = 4019999;

bool HasTable(sqlite3* db, const std::string& path, const std::string& table) {
  Statement stmt(db, path, "SELECT 1 FROM sqlite_master WHERE type='table' AND name=?;");
  stmt.Bind(1, table);
  return stmt.Step();
}

bool HasColumn(sqlite3* db, const std::string& path, const std::string& table,
               const std::string& column) {
  Statement stmt(db, path, "SELECT 1 FROM pragma_table_info(?) WHERE name=?;");
  stmt.Bind(1, table).Bind(2, column);
  return stmt.Step();
}

std::string VersionOfNumber(int64_t user_version) {
  if (user_version < 4000000) return std::to_string(user_version);
  return std::to_string(user_version / 1000000) + "." + std::to_string(user_version / 10000 % 100);
}

}  // namespace

const std::vector<ColmapVersion>& AllColmapVersions() {
  static const std::vector<ColmapVersion> kVersions = {
      ColmapVersion::k3_8,  ColmapVersion::k3_9,  ColmapVersion::k3_10, ColmapVersion::k3_11,
      ColmapVersion::k3_12, ColmapVersion::k3_13, ColmapVersion::k4_0,  ColmapVersion::k4_1};
  return kVersions;
}

std::string ColmapVersionName(ColmapVersion version) {
  static const char* const kNames[] = {"3.8", "3.9", "3.10", "3.11", "3.12", "3.13", "4.0", "4.1"};
  return kNames[static_cast<int>(version)];
}

ColmapVersion ParseColmapVersion(const std::string& name, const std::string& option) {
  std::string names;
  for (const ColmapVersion version : AllColmapVersions()) {
    if (ColmapVersionName(version) == name) return version;
    names += (names.empty() ? "" : ", ") + ColmapVersionName(version);
  }
  throw OptionError(option, name, "a COLMAP version portcal knows: " + names);
}

std::vector<std::pair<std::string, ColmapVersion>> ColmapVersionChoices() {
  std::vector<std::pair<std::string, ColmapVersion>> choices;
  for (const ColmapVersion version : AllColmapVersions())
    choices.emplace_back(ColmapVersionName(version), version);
  return choices;
}

int64_t ColmapUserVersion(ColmapVersion version) {
  switch (version) {
    case ColmapVersion::k3_8:
      return 3800;
    case ColmapVersion::k4_0:
      return 4000000;
    case ColmapVersion::k4_1:
      return 4010000;
    default:
      return 3900;  // 3.9 to 3.13 all write 3900
  }
}

ColmapLayout LayoutOf(ColmapVersion version) {
  const int v = static_cast<int>(version);
  ColmapLayout layout;
  layout.user_version = ColmapUserVersion(version);
  layout.image_prior_columns = v <= static_cast<int>(ColmapVersion::k3_9);
  layout.pose_priors = v <= static_cast<int>(ColmapVersion::k3_9) ? ColmapLayout::PosePriors::kNone
                       : v <= static_cast<int>(ColmapVersion::k3_13)
                           ? ColmapLayout::PosePriors::kPerImage
                           : ColmapLayout::PosePriors::kPerData;
  layout.pose_prior_covariance = v >= static_cast<int>(ColmapVersion::k3_11);
  layout.rigs_and_frames = v >= static_cast<int>(ColmapVersion::k3_12);
  layout.descriptor_type = v >= static_cast<int>(ColmapVersion::k4_0);
  return layout;
}

std::string ColmapLayout::VersionRange() const {
  if (user_version == 3800) return "COLMAP 3.8";
  if (user_version >= 4000000) return "COLMAP " + VersionOfNumber(user_version);
  if (rigs_and_frames) return "COLMAP 3.12-3.13";
  if (pose_prior_covariance) return "COLMAP 3.11";
  if (pose_priors != PosePriors::kNone) return "COLMAP 3.10";
  return "COLMAP 3.9";
}

ColmapVersion NewestVersionWith(const ColmapLayout& layout) {
  ColmapVersion newest = ColmapVersion::k3_8;
  for (const ColmapVersion version : AllColmapVersions()) {
    const ColmapLayout candidate = LayoutOf(version);
    const bool same_number = layout.user_version >= 4000000
                                 ? candidate.user_version / 10000 == layout.user_version / 10000
                                 : candidate.user_version == layout.user_version;
    if (same_number && candidate.pose_priors == layout.pose_priors &&
        candidate.rigs_and_frames == layout.rigs_and_frames &&
        candidate.descriptor_type == layout.descriptor_type &&
        candidate.pose_prior_covariance == layout.pose_prior_covariance) {
      newest = version;
    }
  }
  return newest;
}

ColmapLayout DetectColmapLayout(sqlite3* db, const std::string& path) {
  for (const char* table :
       {"cameras", "images", "keypoints", "descriptors", "matches", "two_view_geometries"}) {
    if (!HasTable(db, path, table)) {
      throw DatabaseError(path + ": no table '" + table + "': not a COLMAP database");
    }
  }
  ColmapLayout layout;
  Statement version(db, path, "PRAGMA user_version;");
  layout.user_version = version.Step() ? version.ColumnInt64(0) : 0;
  if (layout.user_version > kNewestKnownUserVersion) {
    throw DatabaseError(path + ": a database of COLMAP " + VersionOfNumber(layout.user_version) +
                        " (user_version " + std::to_string(layout.user_version) +
                        "), newer than portcal knows (COLMAP 3.8 to 4.1, " + "user_version up to " +
                        std::to_string(kNewestKnownUserVersion) + ")");
  }
  if (layout.user_version != 3800 && layout.user_version != 3900 && layout.user_version < 4000000) {
    throw DatabaseError(
        path + ": database schema version " + std::to_string(layout.user_version) +
        ", none of COLMAP 3.8 to 4.1's (3800, 3900, 4000000 and up); open it once with "
        "COLMAP 3.8 or newer to bring it up to date, or start a new database");
  }
  layout.image_prior_columns = HasColumn(db, path, "images", "prior_qw");
  if (HasTable(db, path, "pose_priors")) {
    layout.pose_priors = HasColumn(db, path, "pose_priors", "corr_data_id")
                             ? ColmapLayout::PosePriors::kPerData
                             : ColmapLayout::PosePriors::kPerImage;
    layout.pose_prior_covariance = HasColumn(db, path, "pose_priors", "position_covariance");
  } else {
    layout.pose_priors = ColmapLayout::PosePriors::kNone;
  }
  layout.rigs_and_frames = HasTable(db, path, "rigs") && HasTable(db, path, "frames") &&
                           HasTable(db, path, "frame_data") && HasTable(db, path, "rig_sensors");
  layout.descriptor_type = HasColumn(db, path, "descriptors", "type");
  if (layout.pose_priors == ColmapLayout::PosePriors::kNone && !layout.image_prior_columns) {
    throw DatabaseError(
        path +
        ": the images table has no prior_* columns and there is no pose_priors table: "
        "no COLMAP version writes that");
  }
  return layout;
}

}  // namespace portcal
