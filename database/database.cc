#include "database/database.h"

#include <sqlite3.h>

#include <cmath>
#include <cstring>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "database/lock_wait.h"
#include "database/schema.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Pixel coordinates beyond any image (sides are at most 65 535 px) by a
// wide margin: keypoints a little outside the image are COLMAP's habit.
constexpr float kMaxKeypointCoordinate = 1 << 20;

template <typename T>
std::vector<T> BlobAs(const std::vector<uint8_t>& blob) {
  std::vector<T> values(blob.size() / sizeof(T));
  if (!values.empty()) std::memcpy(values.data(), blob.data(), values.size() * sizeof(T));
  return values;
}

// Every image's camera is in the file. SQLite enforces the foreign key only
// on writes with foreign_keys on, so a file edited without it (or damaged)
// can hold an image of a camera that is not there; every stage reads
// cameras by their id. Costs one index look-up per image.
void CheckImagesHaveCameras(sqlite3* db, const std::string& path) {
  Statement stmt(db, path,
                 "SELECT image_id, name, camera_id FROM images WHERE camera_id NOT IN "
                 "(SELECT camera_id FROM cameras) ORDER BY image_id LIMIT 1;");
  if (!stmt.Step()) return;
  throw InputError(path + ": image " + std::to_string(stmt.ColumnInt64(0)) + " (" +
                   stmt.ColumnText(1) + ") refers to camera " +
                   std::to_string(stmt.ColumnInt64(2)) +
                   ", which the database does not hold (a damaged or hand-edited file; `sqlite3 " +
                   path + " 'PRAGMA foreign_key_check'` lists such rows)");
}

}  // namespace

Database::Database(const fs::path& path, OpenMode mode, ColmapVersion version_if_created)
    : path_(path.string()) {
  const bool exists = fs::exists(path);
  if (!exists && mode != OpenMode::kCreate) {
    throw DatabaseError(path_ + ": no such database file");
  }
  if (exists && fs::is_directory(path)) {
    throw DatabaseError(path_ + ": is a directory, not a database file");
  }
  const int flags = mode == OpenMode::kReadOnly ? SQLITE_OPEN_READONLY
                                                : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  if (sqlite3_open_v2(path_.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw DatabaseError(path_ + ": cannot open database: " + message);
  }
  try {
    lock_wait_ = std::make_unique<LockWait>(path_, DatabaseBusyTimeout());
    lock_wait_->Install(db_);
    // Fails with "file is not a database" for other files.
    const int64_t num_tables = QueryInt("SELECT count(*) FROM sqlite_master WHERE type='table';");
    if (mode != OpenMode::kReadOnly) {
      ExecuteSql(db_, path_, "PRAGMA foreign_keys = ON;");
    }
    if (num_tables == 0) {
      if (mode == OpenMode::kReadOnly) {
        throw DatabaseError(path_ + ": empty database (no COLMAP tables)");
      }
      CreateSchema(version_if_created);
    }
    CheckSchema();
    CheckImagesHaveCameras(db_, path_);
  } catch (...) {
    statements_.clear();
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

Database::~Database() {
  statements_.clear();
  if (db_ != nullptr) sqlite3_close(db_);
}

Transaction Database::BeginTransaction() { return Transaction(db_, path_); }

void Database::CreateSchema(ColmapVersion version) {
  // COLMAP's tables and portcal's in one transaction: a process killed
  // while creating the database leaves it empty or whole.
  Transaction transaction(db_, path_);
  for (const std::string& sql : ColmapSchemaSql(version)) ExecuteSql(db_, path_, sql + ";");
  ExecuteSql(db_, path_,
             "PRAGMA user_version = " + std::to_string(ColmapUserVersion(version)) + ";");
  for (const std::string& sql : PortcalSchemaSql()) ExecuteSql(db_, path_, sql + ";");
  Statement stmt(db_, path_, "INSERT INTO portcal_meta(key, value) VALUES('schema_version', ?);");
  stmt.Bind(1, std::to_string(kPortcalSchemaVersion)).Execute();
  transaction.Commit();
}

void Database::CheckSchema() {
  layout_ = DetectColmapLayout(db_, path_);
  const int64_t has_meta =
      QueryInt("SELECT count(*) FROM sqlite_master WHERE name='portcal_meta';");
  if (has_meta == 1) {
    Statement stmt(db_, path_, "SELECT value FROM portcal_meta WHERE key='schema_version';");
    const std::string value = stmt.Step() ? stmt.ColumnText(0) : "";
    if (value == "1" && sqlite3_db_readonly(db_, "main") != 1) {
      // Version 2 added a table; the others are as they were.
      Transaction transaction(db_, path_);
      for (const std::string& sql : PortcalSchemaSql()) ExecuteSql(db_, path_, sql + ";");
      Statement update(db_, path_, "UPDATE portcal_meta SET value=? WHERE key='schema_version';");
      update.Bind(1, std::to_string(kPortcalSchemaVersion)).Execute();
      transaction.Commit();
      return;
    }
    // Version 1 read-only: its tables are a subset of version 2's.
    if (value != std::to_string(kPortcalSchemaVersion) && value != "1") {
      throw DatabaseError(path_ + ": portcal tables of schema version '" + value +
                          "', this portcal reads version " + std::to_string(kPortcalSchemaVersion));
    }
    return;
  }
  if (sqlite3_db_readonly(db_, "main") == 1) return;  // read-only: leave as is
  // A database made by COLMAP: add portcal's tables.
  Transaction transaction(db_, path_);
  for (const std::string& sql : PortcalSchemaSql()) ExecuteSql(db_, path_, sql + ";");
  Statement stmt(db_, path_, "INSERT INTO portcal_meta(key, value) VALUES('schema_version', ?);");
  stmt.Bind(1, std::to_string(kPortcalSchemaVersion)).Execute();
  transaction.Commit();
}

Statement& Database::Prepare(const std::string& key, const std::string& sql) {
  auto it = statements_.find(key);
  if (it == statements_.end()) {
    it = statements_.emplace(key, std::make_unique<Statement>(db_, path_, sql)).first;
  }
  it->second->Reset();
  return *it->second;
}

int64_t Database::QueryInt(const std::string& sql) {
  Statement stmt(db_, path_, sql);
  if (!stmt.Step()) return 0;
  return stmt.ColumnInt64(0);
}

// --- features --------------------------------------------------------------

void Database::WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints) {
  static_assert(sizeof(FeatureKeypoint) == 6 * sizeof(float));
  Statement& stmt =
      Prepare("write_keypoints",
              "INSERT OR REPLACE INTO keypoints(image_id, rows, cols, data) VALUES(?, ?, 6, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .Bind(2, static_cast<int64_t>(keypoints.size()))
      .BindBlob(3, keypoints.data(), keypoints.size() * sizeof(FeatureKeypoint));
  stmt.Execute();
}

std::string Database::ImageLabel(image_t image_id) {
  const std::optional<DatabaseImage> image = ReadImage(image_id);
  return "image " + std::to_string(image_id) + (image ? " (" + image->name + ")" : std::string());
}

FeatureKeypoints Database::ReadKeypoints(image_t image_id) {
  Statement& stmt =
      Prepare("read_keypoints", "SELECT rows, cols, data FROM keypoints WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  FeatureKeypoints keypoints;
  if (!stmt.Step()) return keypoints;
  const int64_t rows = stmt.ColumnInt64(0);
  const int64_t cols = stmt.ColumnInt64(1);
  const std::vector<float> data = BlobAs<float>(stmt.ColumnBlob(2));
  if (rows < 0 || (cols != 2 && cols != 4 && cols != 6) ||
      static_cast<int64_t>(data.size()) != rows * cols) {
    throw DatabaseError(path_ + ": keypoints of " + ImageLabel(image_id) +
                        " have an invalid blob (" + std::to_string(rows) + " x " +
                        std::to_string(cols) + ", " + std::to_string(data.size()) + " floats)");
  }
  // A damaged or edited blob: NaN, inf or 3e38 would pass the matchers,
  // the masker and the mapper as if they were points.
  for (size_t i = 0; i < data.size(); ++i) {
    const bool coordinate = i % cols < 2;
    if (!std::isfinite(data[i]) || (coordinate && std::abs(data[i]) > kMaxKeypointCoordinate)) {
      throw InputError(path_ + ": keypoint " + std::to_string(i / cols) + " of " +
                       ImageLabel(image_id) + " holds " + FormatShortest(data[i]) +
                       (coordinate ? " as a coordinate" : " in its shape") +
                       " (a damaged or edited database: extract this image's features again)");
    }
  }
  keypoints.resize(rows);
  for (int64_t i = 0; i < rows; ++i) {
    const float* row = data.data() + i * cols;
    if (cols == 2) {
      keypoints[i] = FeatureKeypoint::FromScaleOrientation(row[0], row[1], 1, 0);
    } else if (cols == 4) {
      keypoints[i] = FeatureKeypoint::FromScaleOrientation(row[0], row[1], row[2], row[3]);
    } else {
      keypoints[i] = {row[0], row[1], row[2], row[3], row[4], row[5]};
    }
  }
  return keypoints;
}

void Database::WriteDescriptors(image_t image_id, const FeatureDescriptors& descriptors) {
  // COLMAP 4 records the extractor: SIFT.
  Statement& stmt = Prepare(
      "write_descriptors",
      layout_.descriptor_type
          ? "INSERT OR REPLACE INTO descriptors(image_id, rows, cols, data, type) "
            "VALUES(?, ?, 128, ?, " +
                std::to_string(kDescriptorTypeSift) + ");"
          : "INSERT OR REPLACE INTO descriptors(image_id, rows, cols, data) VALUES(?, ?, 128, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .Bind(2, static_cast<int64_t>(descriptors.rows()))
      .BindBlob(3, descriptors.data(), descriptors.size());
  stmt.Execute();
}

FeatureDescriptors Database::ReadDescriptors(image_t image_id) {
  Statement& stmt = Prepare("read_descriptors",
                            layout_.descriptor_type
                                ? "SELECT rows, cols, data, type FROM descriptors WHERE image_id=?;"
                                : "SELECT rows, cols, data FROM descriptors WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return FeatureDescriptors(0, 128);
  if (layout_.descriptor_type && stmt.ColumnInt64(3) != kDescriptorTypeSift) {
    // COLMAP 4's other extractors (ALIKED: float descriptors) cannot be
    // matched as SIFT.
    throw DatabaseError(
        path_ + ": descriptors of " + ImageLabel(image_id) + " are of type " +
        std::to_string(stmt.ColumnInt64(3)) + " (COLMAP 4's " +
        (stmt.ColumnInt64(3) == 1   ? "ALIKED_N16ROT"
         : stmt.ColumnInt64(3) == 2 ? "ALIKED_N32"
                                    : "not SIFT") +
        "); portcal matches SIFT descriptors (type 0) only: extract this image's features again");
  }
  const int64_t rows = stmt.ColumnInt64(0);
  const int64_t cols = stmt.ColumnInt64(1);
  const std::vector<uint8_t> data = stmt.ColumnBlob(2);
  if (rows < 0 || cols != 128 || static_cast<int64_t>(data.size()) != rows * cols) {
    throw DatabaseError(path_ + ": descriptors of " + ImageLabel(image_id) +
                        " are not uint8 x 128 (" + std::to_string(rows) + " x " +
                        std::to_string(cols) + ")");
  }
  FeatureDescriptors descriptors(rows, 128);
  if (rows > 0) std::memcpy(descriptors.data(), data.data(), data.size());
  return descriptors;
}

bool Database::ExistsKeypoints(image_t image_id) {
  Statement& stmt = Prepare("exists_keypoints", "SELECT 1 FROM keypoints WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  return stmt.Step();
}

bool Database::ExistsDescriptors(image_t image_id) {
  Statement& stmt = Prepare("exists_descriptors", "SELECT 1 FROM descriptors WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  return stmt.Step();
}

}  // namespace portcal
