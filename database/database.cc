#include "database/database.h"

#include <sqlite3.h>

#include <cstring>

#include "colmap_ext/util/error.h"
#include "database/lock_wait.h"
#include "database/schema.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

template <typename T>
std::vector<T> BlobAs(const std::vector<uint8_t>& blob) {
  std::vector<T> values(blob.size() / sizeof(T));
  if (!values.empty()) std::memcpy(values.data(), blob.data(), values.size() * sizeof(T));
  return values;
}

}  // namespace

Database::Database(const fs::path& path, OpenMode mode) : path_(path.string()) {
  const bool exists = fs::exists(path);
  if (!exists && mode != OpenMode::kCreate) {
    throw DatabaseError(path_ + ": no such database file");
  }
  if (exists && fs::is_directory(path)) {
    throw DatabaseError(path_ + ": is a directory, not a database file");
  }
  const int flags = mode == OpenMode::kReadOnly
                        ? SQLITE_OPEN_READONLY
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
    const int64_t num_tables =
        QueryInt("SELECT count(*) FROM sqlite_master WHERE type='table';");
    if (mode != OpenMode::kReadOnly) {
      ExecuteSql(db_, path_, "PRAGMA foreign_keys = ON;");
    }
    if (num_tables == 0) {
      if (mode == OpenMode::kReadOnly) {
        throw DatabaseError(path_ + ": empty database (no COLMAP tables)");
      }
      CreateSchema();
    }
    CheckSchema();
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

void Database::CreateSchema() {
  // COLMAP's tables and portcal's in one transaction: a process killed
  // while creating the database leaves it empty or whole.
  Transaction transaction(db_, path_);
  for (const std::string& sql : ColmapSchemaSql()) ExecuteSql(db_, path_, sql + ";");
  ExecuteSql(db_, path_,
             "PRAGMA user_version = " + std::to_string(kColmapSchemaVersion) + ";");
  for (const std::string& sql : PortcalSchemaSql()) ExecuteSql(db_, path_, sql + ";");
  Statement stmt(db_, path_, "INSERT INTO portcal_meta(key, value) VALUES('schema_version', ?);");
  stmt.Bind(1, std::to_string(kPortcalSchemaVersion)).Execute();
  transaction.Commit();
}

void Database::CheckSchema() {
  const int64_t version = QueryInt("PRAGMA user_version;");
  if (version != kColmapSchemaVersion) {
    throw DatabaseError(path_ + ": database schema version " +
                        std::to_string(version) + ", expected " +
                        std::to_string(kColmapSchemaVersion) +
                        " (COLMAP 3.8); convert it with the COLMAP version "
                        "that wrote it or start a new database");
  }
  const int64_t prior_columns = QueryInt(
      "SELECT count(*) FROM pragma_table_info('images') WHERE name='prior_qw';");
  if (prior_columns != 1) {
    throw DatabaseError(path_ + ": the images table lacks COLMAP 3.8's "
                        "prior_qw..prior_tz columns");
  }
  const int64_t has_meta = QueryInt(
      "SELECT count(*) FROM sqlite_master WHERE name='portcal_meta';");
  if (has_meta == 1) {
    Statement stmt(db_, path_,
                   "SELECT value FROM portcal_meta WHERE key='schema_version';");
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
                          "', this portcal reads version " +
                          std::to_string(kPortcalSchemaVersion));
    }
    return;
  }
  if (sqlite3_db_readonly(db_, "main") == 1) return;  // read-only: leave as is
  // A database made by COLMAP: add portcal's tables.
  Transaction transaction(db_, path_);
  for (const std::string& sql : PortcalSchemaSql()) ExecuteSql(db_, path_, sql + ";");
  Statement stmt(db_, path_,
                 "INSERT INTO portcal_meta(key, value) VALUES('schema_version', ?);");
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

// --- cameras and images ----------------------------------------------------

camera_t Database::WriteCamera(const Camera& camera, bool use_camera_id) {
  camera.Validate(path_ + ": camera");
  Statement& stmt = Prepare(
      "write_camera",
      "INSERT INTO cameras(camera_id, model, width, height, params, "
      "prior_focal_length) VALUES(?, ?, ?, ?, ?, ?);");
  if (use_camera_id) {
    stmt.Bind(1, static_cast<int64_t>(camera.camera_id));
  } else {
    stmt.BindNull(1);
  }
  stmt.Bind(2, static_cast<int64_t>(camera.model_id))
      .Bind(3, static_cast<int64_t>(camera.width))
      .Bind(4, static_cast<int64_t>(camera.height))
      .BindBlob(5, camera.params.data(), camera.params.size() * sizeof(double))
      .Bind(6, static_cast<int64_t>(camera.has_prior_focal_length));
  stmt.Execute();
  return static_cast<camera_t>(sqlite3_last_insert_rowid(db_));
}

void Database::UpdateCamera(const Camera& camera) {
  camera.Validate(path_ + ": camera");
  Statement& stmt = Prepare(
      "update_camera",
      "UPDATE cameras SET model=?, width=?, height=?, params=?, "
      "prior_focal_length=? WHERE camera_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera.model_id))
      .Bind(2, static_cast<int64_t>(camera.width))
      .Bind(3, static_cast<int64_t>(camera.height))
      .BindBlob(4, camera.params.data(), camera.params.size() * sizeof(double))
      .Bind(5, static_cast<int64_t>(camera.has_prior_focal_length))
      .Bind(6, static_cast<int64_t>(camera.camera_id));
  stmt.Execute();
}

bool Database::DeleteCameraIfUnused(camera_t camera_id) {
  Statement& stmt = Prepare("delete_unused_camera",
                            "DELETE FROM cameras WHERE camera_id=? AND NOT EXISTS "
                            "(SELECT 1 FROM images WHERE images.camera_id=?);");
  stmt.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, static_cast<int64_t>(camera_id));
  stmt.Execute();
  if (sqlite3_changes(db_) == 0) return false;
  Statement& housing = Prepare("delete_housing", "DELETE FROM portcal_housings WHERE camera_id=?;");
  housing.Bind(1, static_cast<int64_t>(camera_id));
  housing.Execute();
  return true;
}

namespace {

Camera CameraFromRow(const Statement& stmt, const std::string& path) {
  Camera camera;
  camera.camera_id = static_cast<camera_t>(stmt.ColumnInt64(0));
  camera.model_id = static_cast<int>(stmt.ColumnInt64(1));
  camera.width = stmt.ColumnInt64(2);
  camera.height = stmt.ColumnInt64(3);
  camera.params = BlobAs<double>(stmt.ColumnBlob(4));
  camera.has_prior_focal_length = stmt.ColumnInt64(5) != 0;
  camera.Validate(path + ": camera " + std::to_string(camera.camera_id));
  return camera;
}

DatabaseImage ImageFromRow(const Statement& stmt) {
  DatabaseImage image;
  image.image_id = static_cast<image_t>(stmt.ColumnInt64(0));
  image.name = stmt.ColumnText(1);
  image.camera_id = static_cast<camera_t>(stmt.ColumnInt64(2));
  bool has_prior = true;
  double prior[7];
  for (int i = 0; i < 7; ++i) {
    prior[i] = stmt.ColumnDouble(3 + i);
    has_prior = has_prior && std::isfinite(prior[i]);
  }
  if (has_prior) {
    image.cam_from_world_prior = Rigid3d(
        QuaternionFromWxyz(Eigen::Vector4d(prior[0], prior[1], prior[2], prior[3]))
            .normalized(),
        Eigen::Vector3d(prior[4], prior[5], prior[6]));
  } else if (std::isfinite(prior[4]) && std::isfinite(prior[5]) && std::isfinite(prior[6])) {
    image.position_prior = Eigen::Vector3d(prior[4], prior[5], prior[6]);
  }
  return image;
}

constexpr const char* kSelectImage =
    "SELECT image_id, name, camera_id, prior_qw, prior_qx, prior_qy, "
    "prior_qz, prior_tx, prior_ty, prior_tz FROM images";

}  // namespace

std::optional<Camera> Database::ReadCamera(camera_t camera_id) {
  Statement& stmt = Prepare("read_camera", "SELECT * FROM cameras WHERE camera_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera_id));
  if (!stmt.Step()) return std::nullopt;
  return CameraFromRow(stmt, path_);
}

std::vector<Camera> Database::ReadAllCameras() {
  Statement& stmt = Prepare("read_cameras", "SELECT * FROM cameras ORDER BY camera_id;");
  std::vector<Camera> cameras;
  while (stmt.Step()) cameras.push_back(CameraFromRow(stmt, path_));
  return cameras;
}

image_t Database::WriteImage(const DatabaseImage& image, bool use_image_id) {
  if (image.name.empty()) throw InputError(path_ + ": image without a name");
  Statement& stmt = Prepare(
      "write_image",
      "INSERT INTO images(image_id, name, camera_id, prior_qw, prior_qx, "
      "prior_qy, prior_qz, prior_tx, prior_ty, prior_tz) VALUES(?, ?, ?, ?, "
      "?, ?, ?, ?, ?, ?);");
  if (use_image_id) {
    stmt.Bind(1, static_cast<int64_t>(image.image_id));
  } else {
    stmt.BindNull(1);
  }
  stmt.Bind(2, image.name).Bind(3, static_cast<int64_t>(image.camera_id));
  if (image.cam_from_world_prior) {
    const Eigen::Vector4d wxyz = QuaternionToWxyz(image.cam_from_world_prior->rotation);
    for (int i = 0; i < 4; ++i) stmt.Bind(4 + i, wxyz[i]);
    for (int i = 0; i < 3; ++i) {
      stmt.Bind(8 + i, image.cam_from_world_prior->translation[i]);
    }
  } else if (image.position_prior) {
    for (int i = 4; i <= 7; ++i) stmt.BindNull(i);
    for (int i = 0; i < 3; ++i) stmt.Bind(8 + i, (*image.position_prior)[i]);
  } else {
    for (int i = 4; i <= 10; ++i) stmt.BindNull(i);
  }
  stmt.Execute();
  return static_cast<image_t>(sqlite3_last_insert_rowid(db_));
}

void Database::UpdateImageCamera(image_t image_id, camera_t camera_id) {
  Statement& stmt = Prepare("update_image_camera", "UPDATE images SET camera_id=? WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, static_cast<int64_t>(image_id));
  stmt.Execute();
  if (sqlite3_changes(db_) != 1) {
    throw InputError(path_ + ": no image with id " + std::to_string(image_id) + " to give camera " +
                     std::to_string(camera_id));
  }
}

void Database::UpdatePositionPrior(image_t image_id, const std::optional<Eigen::Vector3d>& position) {
  Statement& stmt = Prepare("update_position_prior",
                            "UPDATE images SET prior_qw=NULL, prior_qx=NULL, prior_qy=NULL, "
                            "prior_qz=NULL, prior_tx=?, prior_ty=?, prior_tz=? WHERE image_id=?;");
  for (int i = 0; i < 3; ++i) {
    if (position) {
      stmt.Bind(1 + i, (*position)[i]);
    } else {
      stmt.BindNull(1 + i);
    }
  }
  stmt.Bind(4, static_cast<int64_t>(image_id));
  stmt.Execute();
  if (sqlite3_changes(db_) != 1) {
    throw InputError(path_ + ": no image with id " + std::to_string(image_id) + " for a position prior");
  }
}

std::optional<DatabaseImage> Database::ReadImage(image_t image_id) {
  Statement& stmt =
      Prepare("read_image", std::string(kSelectImage) + " WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return std::nullopt;
  return ImageFromRow(stmt);
}

std::optional<DatabaseImage> Database::ReadImageWithName(const std::string& name) {
  Statement& stmt =
      Prepare("read_image_name", std::string(kSelectImage) + " WHERE name=?;");
  stmt.Bind(1, name);
  if (!stmt.Step()) return std::nullopt;
  return ImageFromRow(stmt);
}

std::vector<DatabaseImage> Database::ReadAllImages() {
  Statement& stmt =
      Prepare("read_images", std::string(kSelectImage) + " ORDER BY image_id;");
  std::vector<DatabaseImage> images;
  while (stmt.Step()) images.push_back(ImageFromRow(stmt));
  return images;
}

// --- features --------------------------------------------------------------

void Database::WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints) {
  static_assert(sizeof(FeatureKeypoint) == 6 * sizeof(float));
  Statement& stmt = Prepare(
      "write_keypoints",
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
    throw DatabaseError(path_ + ": keypoints of " + ImageLabel(image_id) + " have an invalid blob (" +
                        std::to_string(rows) + " x " + std::to_string(cols) + ", " + std::to_string(data.size()) +
                        " floats)");
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
  Statement& stmt = Prepare(
      "write_descriptors",
      "INSERT OR REPLACE INTO descriptors(image_id, rows, cols, data) VALUES(?, ?, 128, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .Bind(2, static_cast<int64_t>(descriptors.rows()))
      .BindBlob(3, descriptors.data(), descriptors.size());
  stmt.Execute();
}

FeatureDescriptors Database::ReadDescriptors(image_t image_id) {
  Statement& stmt = Prepare("read_descriptors",
                            "SELECT rows, cols, data FROM descriptors WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return FeatureDescriptors(0, 128);
  const int64_t rows = stmt.ColumnInt64(0);
  const int64_t cols = stmt.ColumnInt64(1);
  const std::vector<uint8_t> data = stmt.ColumnBlob(2);
  if (rows < 0 || cols != 128 || static_cast<int64_t>(data.size()) != rows * cols) {
    throw DatabaseError(path_ + ": descriptors of " + ImageLabel(image_id) + " are not uint8 x 128 (" +
                        std::to_string(rows) + " x " + std::to_string(cols) + ")");
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
  Statement& stmt =
      Prepare("exists_descriptors", "SELECT 1 FROM descriptors WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  return stmt.Step();
}

}  // namespace portcal
