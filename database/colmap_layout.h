// The COLMAP versions whose databases portcal opens, creates and converts,
// and the layout an open database has. COLMAP 3.9 to 3.13 all write
// PRAGMA user_version 3900, so the layout is read from the tables
// themselves (docs/database.md has the table of what each version keeps
// where); COLMAP 4 numbers versions major * 10^6 + minor * 10^4 + patch *
// 100 (+ a schema revision).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

struct sqlite3;

namespace portcal {

enum class ColmapVersion { k3_8, k3_9, k3_10, k3_11, k3_12, k3_13, k4_0, k4_1 };

const std::vector<ColmapVersion>& AllColmapVersions();
std::string ColmapVersionName(ColmapVersion version);  // "3.8", "4.1"
// Throws InputError naming `option` and the versions portcal knows.
ColmapVersion ParseColmapVersion(const std::string& name, const std::string& option);
// Each version by name, for a command line's choice.
std::vector<std::pair<std::string, ColmapVersion>> ColmapVersionChoices();
// The PRAGMA user_version COLMAP `version` writes.
int64_t ColmapUserVersion(ColmapVersion version);

// COLMAP's enums as stored in the tables.
constexpr int64_t kSensorTypeCamera = 0;           // SensorType::CAMERA
constexpr int64_t kCoordinateSystemCartesian = 1;  // PosePrior::CoordinateSystem
constexpr int64_t kCoordinateSystemUndefined = -1;
constexpr int64_t kDescriptorTypeSift = 0;  // FeatureExtractorType::SIFT

// Where a database keeps what changed between versions.
struct ColmapLayout {
  enum class PosePriors {
    kNone,      // 3.8, 3.9: images.prior_* only
    kPerImage,  // 3.10-3.13: pose_priors(image_id, position, coordinate_system[,
                // position_covariance])
    kPerData,   // 4.x: pose_priors(pose_prior_id, corr_data_id, corr_sensor_id, corr_sensor_type,
                // ...)
  };
  int64_t user_version = 3800;
  bool image_prior_columns = true;  // images.prior_qw..prior_tz
  PosePriors pose_priors = PosePriors::kNone;
  bool pose_prior_covariance = false;  // position_covariance (3.11+)
  bool rigs_and_frames = false;        // rigs, rig_sensors, frames, frame_data (3.12+)
  bool descriptor_type = false;        // descriptors.type (4.x)

  // COLMAP 4 writes NULL for F, E, H, qvec, tvec it did not estimate
  // (3.x: zeros and the identity, or empty blobs without inliers).
  bool NullForUnset() const { return user_version >= 4000000; }
  // The versions that write this layout, e.g. "COLMAP 3.12-3.13".
  std::string VersionRange() const;
};

// The layout `version` creates.
ColmapLayout LayoutOf(ColmapVersion version);

// The layout of an open database. Throws DatabaseError naming `path` for a
// database without COLMAP's tables and for a user_version portcal does
// not know (a newer COLMAP's: both versions named).
ColmapLayout DetectColmapLayout(sqlite3* db, const std::string& path);

// The newest version whose layout and user_version `layout` has (the
// version a conversion starts from).
ColmapVersion NewestVersionWith(const ColmapLayout& layout);

}  // namespace portcal
