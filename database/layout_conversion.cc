// Database::ConvertTo: a database moved between COLMAP versions' layouts,
// as COLMAP's own migrations move it up (scene/database_sqlite.cc at 4.1.0:
// PreMigrateTables, PostMigrateTables), and back down, keeping every row
// a version can hold and refusing, before anything changes, where it
// cannot.
#include <sqlite3.h>

#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "database/schema.h"

namespace portcal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A camera's pose prior, whichever table holds it.
struct PriorRow {
  int64_t image_id = 0;
  int64_t camera_id = 0;
  std::vector<uint8_t> position;  // 3 float64
  int64_t coordinate_system = kCoordinateSystemUndefined;
  std::vector<uint8_t> covariance;  // 9 float64 or empty
  std::vector<uint8_t> gravity;     // 3 float64 or empty
};

bool AllNaN(const std::vector<uint8_t>& blob) {
  for (size_t i = 0; i + 8 <= blob.size(); i += 8) {
    double value = 0;
    std::memcpy(&value, blob.data() + i, 8);
    if (!std::isnan(value)) return false;
  }
  return true;
}

std::vector<uint8_t> NaNBlob(int count) {
  std::vector<uint8_t> blob(8 * count);
  for (int i = 0; i < count; ++i) std::memcpy(blob.data() + 8 * i, &kNaN, 8);
  return blob;
}

// The camera centre of a legacy prior (prior_tx..tz, then prior_qw..qz):
// the position itself, or with a rotation the centre of the pose.
Eigen::Vector3d LegacyPriorPosition(const Statement& stmt) {
  const Eigen::Vector3d t(stmt.ColumnDouble(2), stmt.ColumnDouble(3), stmt.ColumnDouble(4));
  const Eigen::Vector4d wxyz(stmt.ColumnDouble(5), stmt.ColumnDouble(6), stmt.ColumnDouble(7),
                             stmt.ColumnDouble(8));
  if (!wxyz.allFinite() || !(wxyz.norm() > 0)) return t;
  const Eigen::Quaterniond rotation(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  return -(rotation.normalized().inverse() * t);
}

// The statements of `version`'s schema that create `table` and its index.
std::vector<std::string> CreateStatementsOf(ColmapVersion version, const std::string& table) {
  std::vector<std::string> statements;
  for (const std::string& sql : ColmapSchemaSql(version)) {
    if (sql.find("EXISTS " + table + " ") != std::string::npos ||
        sql.find(" ON    " + table + "(") != std::string::npos) {
      statements.push_back(sql);
    }
  }
  return statements;
}

std::vector<PriorRow> ReadPriorRows(sqlite3* db, const std::string& path,
                                    const ColmapLayout& layout) {
  std::string sql;
  switch (layout.pose_priors) {
    case ColmapLayout::PosePriors::kNone:
      sql =
          "SELECT image_id, camera_id, prior_tx, prior_ty, prior_tz, prior_qw, prior_qx, prior_qy, "
          "prior_qz FROM "
          "images WHERE prior_tx IS NOT NULL AND prior_ty IS NOT NULL AND prior_tz IS NOT NULL "
          "ORDER BY image_id;";
      break;
    case ColmapLayout::PosePriors::kPerImage:
      sql = std::string(
                "SELECT pose_priors.image_id, images.camera_id, position, coordinate_system, ") +
            (layout.pose_prior_covariance ? "position_covariance" : "NULL") +
            " FROM pose_priors JOIN images ON images.image_id = pose_priors.image_id ORDER BY "
            "pose_priors.image_id;";
      break;
    default:
      sql =
          "SELECT corr_data_id, corr_sensor_id, position, coordinate_system, position_covariance, "
          "gravity, "
          "corr_sensor_type FROM pose_priors ORDER BY corr_data_id;";
  }
  Statement stmt(db, path, sql);
  std::vector<PriorRow> rows;
  while (stmt.Step()) {
    PriorRow row;
    row.image_id = stmt.ColumnInt64(0);
    row.camera_id = stmt.ColumnInt64(1);
    if (layout.pose_priors == ColmapLayout::PosePriors::kNone) {
      const Eigen::Vector3d position = LegacyPriorPosition(stmt);
      row.position.resize(24);
      std::memcpy(row.position.data(), position.data(), 24);
    } else {
      row.position = stmt.ColumnBlob(2);
      row.coordinate_system = stmt.ColumnInt64(3);
      row.covariance = stmt.ColumnBlob(4);
    }
    if (layout.pose_priors == ColmapLayout::PosePriors::kPerData) {
      row.gravity = stmt.ColumnBlob(5);
      if (stmt.ColumnInt64(6) != kSensorTypeCamera) {
        throw InputError(path + ": pose prior of sensor " + std::to_string(row.camera_id) +
                         " of type " + std::to_string(stmt.ColumnInt64(6)) +
                         " (not a camera): COLMAP 3.x keeps camera priors only");
      }
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

// What a 3.x target cannot hold of a prior, checked before anything changes.
void CheckPriorsFit(const std::vector<PriorRow>& rows, const ColmapLayout& target,
                    const std::string& path) {
  for (const PriorRow& row : rows) {
    const std::string which = path + ": the pose prior of image " + std::to_string(row.image_id);
    if (target.pose_priors != ColmapLayout::PosePriors::kPerData && !row.gravity.empty() &&
        !AllNaN(row.gravity)) {
      throw InputError(which + " has a gravity direction, which COLMAP 3.x does not keep");
    }
    if (!target.pose_prior_covariance && !row.covariance.empty() && !AllNaN(row.covariance)) {
      throw InputError(which +
                       " has a position covariance, which the target version does not keep");
    }
    if (row.position.size() != 24) throw InputError(which + ": its position is not 3 float64");
  }
}

void AddLegacyPriorColumns(sqlite3* db, const std::string& path) {
  for (const char* column :
       {"prior_qw", "prior_qx", "prior_qy", "prior_qz", "prior_tx", "prior_ty", "prior_tz"}) {
    Statement has(db, path, "SELECT 1 FROM pragma_table_info('images') WHERE name=?;");
    has.Bind(1, std::string(column));
    if (!has.Step())
      ExecuteSql(db, path, std::string("ALTER TABLE images ADD COLUMN ") + column + " REAL;");
  }
}

// Back into prior_*: a row whose legacy columns already hold a pose
// with this centre keeps it (a 3.8 database converted up and back);
// images without a prior lose stale legacy values.
void WriteLegacyPriors(sqlite3* db, const std::string& path, const std::vector<PriorRow>& rows) {
  ExecuteSql(db, path, "CREATE TEMP TABLE portcal_prior_images(image_id INTEGER PRIMARY KEY);");
  for (const PriorRow& row : rows) {
    Statement mark(db, path, "INSERT INTO portcal_prior_images(image_id) VALUES(?);");
    mark.Bind(1, row.image_id).Execute();
    Eigen::Vector3d position;
    std::memcpy(position.data(), row.position.data(), 24);
    Statement current(
        db, path,
        "SELECT image_id, camera_id, prior_tx, prior_ty, prior_tz, prior_qw, prior_qx, prior_qy, "
        "prior_qz FROM images WHERE image_id=? AND prior_tx IS NOT NULL AND prior_ty IS NOT NULL "
        "AND "
        "prior_tz IS NOT NULL;");
    current.Bind(1, row.image_id);
    if (current.Step() &&
        (LegacyPriorPosition(current) - position).norm() <= 1e-9 * (1 + position.norm()))
      continue;
    Statement stmt(
        db, path,
        "UPDATE images SET prior_qw=NULL, prior_qx=NULL, prior_qy=NULL, prior_qz=NULL, prior_tx=?, "
        "prior_ty=?, prior_tz=? WHERE image_id=?;");
    stmt.Bind(1, position[0])
        .Bind(2, position[1])
        .Bind(3, position[2])
        .Bind(4, row.image_id)
        .Execute();
  }
  ExecuteSql(db, path,
             "UPDATE images SET prior_qw=NULL, prior_qx=NULL, prior_qy=NULL, prior_qz=NULL, "
             "prior_tx=NULL, "
             "prior_ty=NULL, prior_tz=NULL WHERE image_id NOT IN (SELECT image_id FROM "
             "portcal_prior_images);");
  ExecuteSql(db, path, "DROP TABLE portcal_prior_images;");
}

void WritePriorRows(sqlite3* db, const std::string& path, const std::vector<PriorRow>& rows,
                    const ColmapLayout& target) {
  if (target.pose_priors == ColmapLayout::PosePriors::kNone) {
    WriteLegacyPriors(db, path, rows);
    return;
  }
  for (const PriorRow& row : rows) {
    const std::vector<uint8_t> covariance =
        row.covariance.size() == 72 ? row.covariance : NaNBlob(9);
    if (target.pose_priors == ColmapLayout::PosePriors::kPerImage) {
      Statement stmt(
          db, path,
          target.pose_prior_covariance
              ? "INSERT INTO pose_priors(image_id, position, coordinate_system, "
                "position_covariance) VALUES(?, ?, ?, ?);"
              : "INSERT INTO pose_priors(image_id, position, coordinate_system) VALUES(?, ?, ?);");
      stmt.Bind(1, row.image_id)
          .BindBlob(2, row.position.data(), 24)
          .Bind(3, row.coordinate_system);
      if (target.pose_prior_covariance) stmt.BindBlob(4, covariance.data(), 72);
      stmt.Execute();
      continue;
    }
    // COLMAP 4's migration: the image id as the prior's id and its data id.
    const std::vector<uint8_t> gravity = row.gravity.size() == 24 ? row.gravity : NaNBlob(3);
    Statement stmt(
        db, path,
        "INSERT INTO pose_priors(pose_prior_id, corr_data_id, corr_sensor_id, corr_sensor_type, "
        "position, "
        "position_covariance, gravity, coordinate_system) VALUES(?, ?, ?, ?, ?, ?, ?, ?);");
    stmt.Bind(1, row.image_id)
        .Bind(2, row.image_id)
        .Bind(3, row.camera_id)
        .Bind(4, kSensorTypeCamera);
    stmt.BindBlob(5, row.position.data(), 24)
        .BindBlob(6, covariance.data(), 72)
        .BindBlob(7, gravity.data(), 24);
    stmt.Bind(8, row.coordinate_system).Execute();
  }
}

bool SamePriorTable(const ColmapLayout& a, const ColmapLayout& b) {
  return a.pose_priors == b.pose_priors && (a.pose_priors == ColmapLayout::PosePriors::kNone ||
                                            a.pose_prior_covariance == b.pose_prior_covariance);
}

}  // namespace

void Database::ConvertTo(ColmapVersion target_version) {
  const ColmapLayout target = LayoutOf(target_version);
  statements_.clear();  // prepared for the old layout's tables
  Transaction transaction(db_, path_);
  ConvertPosePriors(target_version);
  ConvertRigsAndFrames(target_version);
  ConvertDescriptors(target);
  ConvertTwoViewGeometries(target);
  ExecuteSql(db_, path_, "PRAGMA user_version = " + std::to_string(target.user_version) + ";");
  transaction.Commit();
  layout_ = DetectColmapLayout(db_, path_);
}

void Database::CopyTo(const std::filesystem::path& path) {
  Statement stmt(db_, path_, "VACUUM INTO ?;");
  stmt.Bind(1, path.string()).Execute();
}

// Legacy prior_* columns stay where they are (COLMAP's migrations keep
// them, and a 3.8 database converted up and back gets its values back);
// pose_priors is made afresh in the target's form.
void Database::ConvertPosePriors(ColmapVersion target_version) {
  const ColmapLayout target = LayoutOf(target_version);
  if (SamePriorTable(layout_, target)) return;
  const std::vector<PriorRow> rows = ReadPriorRows(db_, path_, layout_);
  CheckPriorsFit(rows, target, path_);
  if (layout_.pose_priors != ColmapLayout::PosePriors::kNone)
    ExecuteSql(db_, path_, "DROP TABLE pose_priors;");
  if (target.pose_priors == ColmapLayout::PosePriors::kNone) {
    AddLegacyPriorColumns(db_, path_);
  } else {
    for (const std::string& sql : CreateStatementsOf(target_version, "pose_priors")) {
      ExecuteSql(db_, path_, sql + ";");
    }
  }
  WritePriorRows(db_, path_, rows, target);
}

// Up: one rig per camera (rig id = camera id, the camera its reference)
// and one frame per image (frame id = image id), what COLMAP 3.12 on
// makes of a database without rigs. Down: only such trivial rigs and
// frames can go, since COLMAP 3.x has no rigs.
void Database::ConvertRigsAndFrames(ColmapVersion target_version) {
  const ColmapLayout target = LayoutOf(target_version);
  if (layout_.rigs_and_frames == target.rigs_and_frames) return;
  if (target.rigs_and_frames) {
    for (const char* table : {"rigs", "rig_sensors", "frames", "frame_data"}) {
      for (const std::string& sql : CreateStatementsOf(target_version, table))
        ExecuteSql(db_, path_, sql + ";");
    }
    const std::string camera = std::to_string(kSensorTypeCamera);
    ExecuteSql(
        db_, path_,
        "INSERT INTO rigs(rig_id, ref_sensor_id, ref_sensor_type) SELECT camera_id, camera_id, " +
            camera + " FROM cameras ORDER BY camera_id;");
    ExecuteSql(db_, path_,
               "INSERT INTO frames(frame_id, rig_id) SELECT image_id, camera_id FROM images ORDER "
               "BY image_id;");
    ExecuteSql(db_, path_,
               "INSERT INTO frame_data(frame_id, data_id, sensor_id, sensor_type) SELECT image_id, "
               "image_id, camera_id, " +
                   camera + " FROM images ORDER BY image_id;");
    return;
  }
  const std::string camera = std::to_string(kSensorTypeCamera);
  // What COLMAP 3.x could not hold, each with how it reads in the refusal.
  const std::vector<std::pair<std::string, std::string>> kept_only_by_rigs = {
      {"SELECT count(*) FROM rig_sensors;", "rig sensors beside the reference cameras"},
      {"SELECT count(*) FROM rigs WHERE ref_sensor_type != " + camera + ";",
       "rigs whose reference sensor is not a camera"},
      {"SELECT count(*) FROM (SELECT frame_id FROM frame_data GROUP BY frame_id HAVING count(*) > "
       "1);",
       "frames of several images"},
      {"SELECT count(*) FROM frame_data WHERE sensor_type != " + camera + ";",
       "data of other sensors"}};
  std::string refused;
  for (const auto& [query, what] : kept_only_by_rigs) {
    const int64_t count = QueryInt(query);
    if (count > 0) refused += (refused.empty() ? "" : ", ") + std::to_string(count) + " " + what;
  }
  if (!refused.empty()) {
    throw InputError(path_ + ": " + refused + ": COLMAP " + ColmapVersionName(target_version) +
                     " has no rigs to keep them (convert to 3.12 or later)");
  }
  for (const char* table : {"frame_data", "frames", "rig_sensors", "rigs"}) {
    ExecuteSql(db_, path_, std::string("DROP TABLE ") + table + ";");
  }
}

// COLMAP 4.1's migration adds the type (SIFT for what was there); down,
// only SIFT descriptors can stay.
void Database::ConvertDescriptors(const ColmapLayout& target) {
  if (layout_.descriptor_type == target.descriptor_type) return;
  if (target.descriptor_type) {
    ExecuteSql(db_, path_,
               "ALTER TABLE descriptors ADD COLUMN type INTEGER NOT NULL DEFAULT " +
                   std::to_string(kDescriptorTypeSift) + ";");
    return;
  }
  const int64_t others = QueryInt("SELECT count(*) FROM descriptors WHERE type != " +
                                  std::to_string(kDescriptorTypeSift) + ";");
  if (others > 0) {
    throw InputError(path_ + ": " + std::to_string(others) +
                     " images have descriptors other than SIFT (COLMAP 4's ALIKED), which COLMAP "
                     "3.x would read as "
                     "SIFT: extract them with SIFT first");
  }
  ExecuteSql(db_, path_, "ALTER TABLE descriptors DROP COLUMN type;");
}

// Up (COLMAP 4.1's migration): zero F, E, H and an identity or zero
// relative pose are "not estimated", NULL. Down: NULL becomes 3.x's
// sentinels again, empty blobs where a pair has no inliers.
void Database::ConvertTwoViewGeometries(const ColmapLayout& target) {
  if (layout_.NullForUnset() == target.NullForUnset()) return;
  if (target.NullForUnset()) {
    const std::string zero_matrix = "zeroblob(72)";
    for (const char* column : {"F", "E", "H"}) {
      ExecuteSql(db_, path_,
                 std::string("UPDATE two_view_geometries SET ") + column + " = NULL WHERE length(" +
                     column + ") = 0 OR " + column + " = " + zero_matrix + ";");
    }
    const Eigen::Vector4d identity(1, 0, 0, 0);
    Statement pose(
        db_, path_,
        "UPDATE two_view_geometries SET qvec = NULL, tvec = NULL WHERE length(qvec) = 0 OR "
        "qvec = zeroblob(32) OR (qvec = ? AND tvec = zeroblob(24));");
    pose.BindBlob(1, identity.data(), 32).Execute();
    return;
  }
  const Eigen::Vector4d identity(1, 0, 0, 0);
  Statement empty(db_, path_,
                  "UPDATE two_view_geometries SET F = COALESCE(F, x''), E = COALESCE(E, x''), H = "
                  "COALESCE(H, x''), "
                  "qvec = COALESCE(qvec, x''), tvec = COALESCE(tvec, x'') WHERE rows = 0;");
  empty.Execute();
  for (const char* column : {"F", "E", "H"}) {
    ExecuteSql(db_, path_,
               std::string("UPDATE two_view_geometries SET ") + column + " = zeroblob(72) WHERE " +
                   column + " IS NULL;");
  }
  Statement pose(db_, path_,
                 "UPDATE two_view_geometries SET qvec = ?, tvec = zeroblob(24) WHERE qvec IS NULL "
                 "OR tvec IS NULL;");
  pose.BindBlob(1, identity.data(), 32).Execute();
}

}  // namespace portcal
