// The database layer: COLMAP's schema and blob layouts, portcal's tables,
// transactions that roll back, and clear errors for files that are not
// databases of the right version, or locked.
#include "database/database.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <future>
#include <thread>

#include "colmap_ext/util/error.h"
#include "database/lock_wait.h"
#include "database/schema.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

Camera TestCamera() {
  Camera camera = Camera::FromModelName("RADIAL", 1297.3655, 1920, 1080);
  camera.params[3] = -0.1;
  camera.has_prior_focal_length = true;
  return camera;
}

// Runs raw SQL through the C API, outside the Database class.
void RawSql(const fs::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  sqlite3_close(db);
}

TEST(Database, CreatesCOLMAP38Schema) {
  testing::TempDir dir;
  Database db(dir / "db.db", Database::OpenMode::kCreate);
  EXPECT_EQ(db.NumCameras(), 0);
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "db.db").c_str(), &raw), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(raw, "PRAGMA user_version;", -1, &stmt, nullptr);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(stmt, 0), 3800);
  sqlite3_finalize(stmt);
  sqlite3_prepare_v2(raw, "SELECT name FROM sqlite_master WHERE type='table' ORDER BY name;", -1,
                     &stmt, nullptr);
  std::vector<std::string> tables;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    tables.emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0)));
  }
  sqlite3_finalize(stmt);
  sqlite3_close(raw);
  for (const char* table :
       {"cameras", "images", "keypoints", "descriptors", "matches", "two_view_geometries",
        "portcal_housings", "portcal_target_observations", "portcal_marker_detections",
        "portcal_stage_log"}) {
    EXPECT_NE(std::find(tables.begin(), tables.end(), table), tables.end()) << table;
  }
}

TEST(Database, PairIdsFollowCOLMAP) {
  EXPECT_EQ(ImagePairToPairId(1, 2), 2147483647ULL + 2);
  EXPECT_EQ(ImagePairToPairId(2, 1), 2147483647ULL + 2);
  image_t a, b;
  PairIdToImagePair(ImagePairToPairId(17, 4), &a, &b);
  EXPECT_EQ(a, 4u);
  EXPECT_EQ(b, 17u);
}

TEST(Database, WritesAndReadsEveryTable) {
  testing::TempDir dir;
  Database db(dir / "db.db", Database::OpenMode::kCreate);
  Transaction transaction = db.BeginTransaction();
  const camera_t camera_id = db.WriteCamera(TestCamera());
  DatabaseImage image1;
  image1.name = "a.png";
  image1.camera_id = camera_id;
  DatabaseImage image2 = image1;
  image2.name = "b.png";
  image2.cam_from_world_prior =
      Rigid3d(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5), Eigen::Vector3d(1, 2, 3));
  const image_t id1 = db.WriteImage(image1);
  const image_t id2 = db.WriteImage(image2);

  FeatureKeypoints keypoints = {FeatureKeypoint::FromScaleOrientation(10.5, 20.25, 2.0, 0.3),
                                FeatureKeypoint::FromScaleOrientation(30, 40, 1.5, -1.0)};
  db.WriteKeypoints(id1, keypoints);
  FeatureDescriptors descriptors(2, 128);
  for (int i = 0; i < descriptors.size(); ++i) descriptors.data()[i] = i % 251;
  db.WriteDescriptors(id1, descriptors);
  db.WriteMatches(id2, id1, {{0, 1}, {1, 0}});  // swapped order on purpose
  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometryConfig::kCalibrated;
  geometry.F << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  geometry.E = geometry.F * 2;
  geometry.H = Eigen::Matrix3d::Identity() * 3;
  geometry.cam2_from_cam1 =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(1, 0, 0));
  geometry.inlier_matches = {{0, 1}};
  db.WriteTwoViewGeometry(id1, id2, geometry);
  db.WriteHousing(camera_id,
                  Housing::FromName("FLATPORT", {0, 0, 1, 0.02, 0.014, 1, 1.473, 1.334}, "t"));
  db.WriteTargetObservations(id1, {{5, {100.25, 200.5}, {0.02, 0.04, 0}}});
  MarkerDetection marker;
  marker.dictionary = "DICT_4X4_50";
  marker.marker_id = 3;
  marker.corners = {Eigen::Vector2d(1, 2), Eigen::Vector2d(3, 4), Eigen::Vector2d(5, 6),
                    Eigen::Vector2d(7, 8)};
  db.WriteMarkerDetections(id2, {marker, marker});
  StageLogEntry entry;
  entry.stage = "test";
  entry.options = "a=1\n";
  entry.start_time = entry.end_time = "2026-01-01T00:00:00Z";
  entry.status = "succeeded";
  entry.counts = "images=2\n";
  db.WriteStageLog(entry);
  transaction.Commit();

  Database reopened(dir / "db.db", Database::OpenMode::kReadOnly);
  const std::optional<Camera> camera = reopened.ReadCamera(camera_id);
  ASSERT_TRUE(camera);
  EXPECT_EQ(camera->params, TestCamera().params);
  EXPECT_TRUE(camera->has_prior_focal_length);
  EXPECT_EQ(reopened.ReadAllImages().size(), 2u);
  EXPECT_FALSE(reopened.ReadImage(id1)->cam_from_world_prior.has_value());
  const auto prior = reopened.ReadImageWithName("b.png")->cam_from_world_prior;
  ASSERT_TRUE(prior);
  EXPECT_EQ(prior->translation, Eigen::Vector3d(1, 2, 3));
  const FeatureKeypoints read_keypoints = reopened.ReadKeypoints(id1);
  ASSERT_EQ(read_keypoints.size(), 2u);
  EXPECT_EQ(read_keypoints[0].x, 10.5f);
  EXPECT_NEAR(read_keypoints[0].ComputeScale(), 2.0f, 1e-6);
  EXPECT_NEAR(read_keypoints[1].ComputeOrientation(), -1.0f, 1e-6);
  EXPECT_EQ(reopened.ReadDescriptors(id1), descriptors);
  const FeatureMatches matches = reopened.ReadMatches(id1, id2);
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0].point2D_idx1, 1u);  // stored as (id1, id2) columns
  EXPECT_EQ(matches[0].point2D_idx2, 0u);
  const auto read_geometry = reopened.ReadTwoViewGeometry(id1, id2);
  ASSERT_TRUE(read_geometry);
  EXPECT_EQ(read_geometry->F, geometry.F);
  EXPECT_EQ(read_geometry->config, TwoViewGeometryConfig::kCalibrated);
  const auto swapped = reopened.ReadTwoViewGeometry(id2, id1);
  EXPECT_EQ(swapped->F, geometry.F.transpose());
  EXPECT_EQ(swapped->inlier_matches[0].point2D_idx1, 1u);
  EXPECT_EQ(reopened.ReadHousing(camera_id)->ModelName(), "FLATPORT");
  EXPECT_EQ(reopened.ReadTargetObservations(id1)[0].point_id, 5);
  EXPECT_EQ(reopened.ReadMarkerDetections(id2).size(), 2u);
  EXPECT_EQ(reopened.ReadStageLog().at(0).counts, "images=2\n");
  EXPECT_EQ(reopened.NumKeypoints(), 2);
  EXPECT_EQ(reopened.NumMatches(), 2);
  EXPECT_EQ(reopened.NumInlierMatches(), 1);
}

TEST(Database, ReadsTwoAndFourColumnKeypoints) {
  testing::TempDir dir;
  {
    Database db(dir / "db.db", Database::OpenMode::kCreate);
    const camera_t camera_id = db.WriteCamera(TestCamera());
    DatabaseImage image;
    image.name = "a.png";
    image.camera_id = camera_id;
    db.WriteImage(image);
    image.name = "b.png";
    db.WriteImage(image);
  }
  const float four[] = {1, 2, 3, 0.5f};
  const float two[] = {7, 8};
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "db.db").c_str(), &raw), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(raw, "INSERT INTO keypoints VALUES(?, 1, ?, ?);", -1, &stmt, nullptr);
  sqlite3_bind_int(stmt, 1, 1);
  sqlite3_bind_int(stmt, 2, 4);
  sqlite3_bind_blob(stmt, 3, four, sizeof(four), SQLITE_STATIC);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_DONE);
  sqlite3_reset(stmt);
  sqlite3_bind_int(stmt, 1, 2);
  sqlite3_bind_int(stmt, 2, 2);
  sqlite3_bind_blob(stmt, 3, two, sizeof(two), SQLITE_STATIC);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_DONE);
  sqlite3_finalize(stmt);
  sqlite3_close(raw);
  Database db(dir / "db.db");
  const FeatureKeypoint k4 = db.ReadKeypoints(1).at(0);
  EXPECT_NEAR(k4.ComputeScale(), 3.0f, 1e-6);
  EXPECT_NEAR(k4.ComputeOrientation(), 0.5f, 1e-6);
  const FeatureKeypoint k2 = db.ReadKeypoints(2).at(0);
  EXPECT_EQ(k2.x, 7.0f);
  EXPECT_NEAR(k2.ComputeScale(), 1.0f, 1e-6);
}

TEST(Database, UncommittedTransactionRollsBack) {
  testing::TempDir dir;
  {
    Database db(dir / "db.db", Database::OpenMode::kCreate);
    db.WriteCamera(TestCamera());
  }
  const std::string before = testing::ReadFileToString(dir / "db.db");
  {
    Database db(dir / "db.db");
    try {
      Transaction transaction = db.BeginTransaction();
      db.WriteCamera(TestCamera());
      DatabaseImage image;
      image.name = "x.png";
      image.camera_id = 1;
      db.WriteImage(image);
      throw InputError("stage failed half way");
    } catch (const InputError&) {
    }
    EXPECT_EQ(db.NumCameras(), 1);
    EXPECT_EQ(db.NumImages(), 0);
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);
}

TEST(Database, ForeignKeysProtectPortcalTables) {
  testing::TempDir dir;
  Database db(dir / "db.db", Database::OpenMode::kCreate);
  EXPECT_THROW(db.WriteTargetObservations(99, {{1, {1, 2}, {0, 0, 0}}}), DatabaseError);
  EXPECT_THROW(db.WriteKeypoints(99, {}), DatabaseError);
}

TEST(Database, ClearErrorsForBadFiles) {
  testing::TempDir dir;
  const auto message = [](const fs::path& path, Database::OpenMode mode) {
    try {
      Database db(path, mode);
    } catch (const DatabaseError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // Missing file.
  EXPECT_NE(message(dir / "missing.db", Database::OpenMode::kReadWrite).find("missing.db"),
            std::string::npos);
  // Not a database.
  std::ofstream(dir / "text.db")
      << "this is not an sqlite database, just some text that is long enough to matter";
  const std::string not_db = message(dir / "text.db", Database::OpenMode::kReadWrite);
  EXPECT_NE(not_db.find("text.db"), std::string::npos);
  EXPECT_NE(not_db.find("not a database"), std::string::npos) << not_db;
  // A newer COLMAP's database: both versions named.
  { Database db(dir / "new.db", Database::OpenMode::kCreate); }
  RawSql(dir / "new.db", "PRAGMA user_version = 4020000;");
  const std::string version = message(dir / "new.db", Database::OpenMode::kReadWrite);
  EXPECT_NE(version.find("COLMAP 4.2"), std::string::npos) << version;
  EXPECT_NE(version.find("COLMAP 3.8 to 4.1"), std::string::npos) << version;
  EXPECT_NE(version.find("new.db"), std::string::npos) << version;
  // An older one, from before user_version was numbered as now.
  { Database db(dir / "old.db", Database::OpenMode::kCreate); }
  RawSql(dir / "old.db", "PRAGMA user_version = 3600;");
  EXPECT_NE(message(dir / "old.db", Database::OpenMode::kReadWrite).find("3600"),
            std::string::npos);
  // portcal tables of another version.
  { Database db(dir / "p.db", Database::OpenMode::kCreate); }
  RawSql(dir / "p.db", "UPDATE portcal_meta SET value='7' WHERE key='schema_version';");
  EXPECT_NE(message(dir / "p.db", Database::OpenMode::kReadWrite).find("'7'"), std::string::npos);
}

// portcal's tables of version 1 (before portcal_unmasked_features): read
// as they are, upgraded in place when opened for writing.
TEST(Database, PortcalTablesOfVersionOneAreUpgraded) {
  testing::TempDir dir;
  camera_t camera_id = 0;
  {
    Database db(dir / "v1.db", Database::OpenMode::kCreate);
    camera_id = db.WriteCamera(TestCamera());
  }
  RawSql(dir / "v1.db", "DROP TABLE portcal_unmasked_features;");
  RawSql(dir / "v1.db", "UPDATE portcal_meta SET value='1' WHERE key='schema_version';");
  {
    Database db(dir / "v1.db", Database::OpenMode::kReadOnly);
    EXPECT_TRUE(db.ReadCamera(camera_id).has_value());
  }
  Database db(dir / "v1.db", Database::OpenMode::kReadWrite);
  EXPECT_EQ(db.NumImagesWithUnmaskedFeatures(), 0);
  EXPECT_TRUE(db.ReadCamera(camera_id).has_value());
}

TEST(Database, LockedDatabaseIsAClearError) {
  testing::TempDir dir;
  SetDatabaseBusyTimeout(0.2);  // not the 60 s default
  Database writer(dir / "db.db", Database::OpenMode::kCreate);
  Transaction hold = writer.BeginTransaction();
  writer.WriteCamera(TestCamera());
  Database other(dir / "db.db");
  try {
    Transaction transaction = other.BeginTransaction();
    FAIL() << "expected DatabaseError";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("locked"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("db.db"), std::string::npos) << e.what();
  }
  SetDatabaseBusyTimeout(60);
}

// Images a, b and c (ids 1, 2, 3) of one camera.
void WriteImagesABC(Database* db) {
  const camera_t camera_id = db->WriteCamera(TestCamera());
  for (const char* name : {"a", "b", "c"}) {
    DatabaseImage image;
    image.name = name;
    image.camera_id = camera_id;
    db->WriteImage(image);
  }
}

TEST(Database, DeleteMatchesOfImageRemovesBothDirections) {
  testing::TempDir dir;
  Database db(dir / "db.db", Database::OpenMode::kCreate);
  WriteImagesABC(&db);
  db.WriteMatches(1, 2, {{0, 0}});
  db.WriteMatches(2, 3, {{0, 0}});
  db.WriteMatches(1, 3, {{0, 0}});
  TwoViewGeometry geometry;
  geometry.inlier_matches = {{0, 0}};
  db.WriteTwoViewGeometry(2, 3, geometry);
  db.DeleteMatchesOfImage(2);
  EXPECT_TRUE(db.ReadMatches(1, 2).empty());
  EXPECT_TRUE(db.ReadMatches(2, 3).empty());
  EXPECT_EQ(db.ReadMatches(1, 3).size(), 1u);
  EXPECT_FALSE(db.ReadTwoViewGeometry(2, 3).has_value());
}

// The partition's weights: each verified pair's inlier count, pairs without
// inliers (failed verification) left out.
TEST(Database, NumInliersOfEachVerifiedPairWithoutTheMatches) {
  testing::TempDir dir;
  Database db(dir / "db.db", Database::OpenMode::kCreate);
  WriteImagesABC(&db);
  TwoViewGeometry geometry;
  geometry.inlier_matches = {{0, 0}, {1, 1}, {2, 2}};
  db.WriteTwoViewGeometry(1, 3, geometry);
  db.WriteTwoViewGeometry(2, 3, TwoViewGeometry());
  geometry.inlier_matches = {{4, 5}};
  db.WriteTwoViewGeometry(2, 1, geometry);
  const std::vector<std::pair<image_pair_t, int>> expected = {{ImagePairToPairId(1, 2), 1},
                                                              {ImagePairToPairId(1, 3), 3}};
  EXPECT_EQ(db.ReadTwoViewGeometryNumInliers(), expected);
}

// Another process holds the write lock for 1.5 s (here another connection,
// on a thread): a stage waits for it, up to --Database.busy_timeout,
// instead of failing after a second; with a shorter timeout it fails with
// a message that names the option.
TEST(Database, AWriterWaitsForAnotherConnectionsLockUpToTheBusyTimeout) {
  testing::TempDir dir;
  { Database create(dir / "a.db", Database::OpenMode::kCreate); }
  Database holder(dir / "a.db", Database::OpenMode::kReadWrite);
  const auto hold = [&](double seconds, std::promise<void>* held) {
    Transaction transaction = holder.BeginTransaction();
    held->set_value();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  };
  SetDatabaseBusyTimeout(10);
  {
    Database waiter(dir / "a.db", Database::OpenMode::kReadWrite);
    std::promise<void> held;
    std::thread holding(hold, 1.5, &held);
    held.get_future().wait();
    const auto start = std::chrono::steady_clock::now();
    { Transaction transaction = waiter.BeginTransaction(); }
    EXPECT_GT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
    holding.join();
  }
  SetDatabaseBusyTimeout(0.3);
  {
    Database waiter(dir / "a.db", Database::OpenMode::kReadWrite);
    std::promise<void> held;
    std::thread holding(hold, 1.5, &held);
    held.get_future().wait();
    try {
      Transaction transaction = waiter.BeginTransaction();
      ADD_FAILURE() << "no wait limit";
    } catch (const DatabaseError& e) {
      EXPECT_NE(std::string(e.what()).find("--Database.busy_timeout"), std::string::npos)
          << e.what();
    }
    holding.join();
  }
  SetDatabaseBusyTimeout(60);
  EXPECT_THROW(SetDatabaseBusyTimeout(-1), OptionError);
}

}  // namespace
}  // namespace portcal
