// Fuzz target: the rows of a database that portcal decodes -- camera
// parameters, keypoints, descriptors, matches, two-view geometries (their
// inliers, config, F/E/H, qvec/tvec), housings, masked-away features, target
// observations and marker corners -- as a database edited or damaged by
// another tool would hold them. The input fills one camera, two images and
// each table's row; then every reader runs on them. DatabaseError and
// InputError name the database; anything else is a finding.
#include <sqlite3.h>

#include <memory>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

using portcal::fuzz::FieldReader;

// Binds the statement's parameters from the input: integers, doubles and
// blobs by their '?N' kinds given in `kinds` ('i', 'd', 'b').
void InsertRow(sqlite3* db, const char* sql, const std::string& kinds, FieldReader* in) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr) != SQLITE_OK) std::abort();
  std::vector<std::string> blobs(kinds.size());
  for (size_t k = 0; k < kinds.size(); ++k) {
    const int index = static_cast<int>(k) + 1;
    if (kinds[k] == 'i') sqlite3_bind_int64(stmt, index, in->TakeIn(-2, 300));
    if (kinds[k] == 'd') sqlite3_bind_double(stmt, index, in->Take<double>());
    if (kinds[k] == 'b') {
      blobs[k] = in->TakeBytes(4096);
      sqlite3_bind_blob(stmt, index, blobs[k].data(), static_cast<int>(blobs[k].size()),
                        SQLITE_STATIC);
    }
  }
  sqlite3_step(stmt);  // a row the schema refuses (NOT NULL, a key twice) is simply not there
  sqlite3_finalize(stmt);
}

void Fill(sqlite3* db, FieldReader* in) {
  sqlite3_exec(
      db,
      "BEGIN; DELETE FROM cameras; DELETE FROM images; DELETE FROM keypoints; DELETE FROM "
      "descriptors; "
      "DELETE FROM matches; DELETE FROM two_view_geometries; DELETE FROM portcal_housings; "
      "DELETE FROM portcal_unmasked_features; DELETE FROM portcal_target_observations; "
      "DELETE FROM portcal_target_detections; DELETE FROM portcal_marker_detections;",
      nullptr, nullptr, nullptr);
  InsertRow(db, "INSERT INTO cameras VALUES (1, ?1, ?2, ?3, ?4, 0)", "iiib", in);
  sqlite3_exec(
      db,
      "INSERT INTO images(image_id, name, camera_id) VALUES (1, 'a.png', 1), (2, 'b.png', 1);"
      "INSERT INTO portcal_target_detections VALUES (1, 'chessboard', 1, 1, ''), (2, 'chessboard', "
      "1, 1, '');",
      nullptr, nullptr, nullptr);
  InsertRow(db, "INSERT INTO keypoints VALUES (1, ?1, ?2, ?3)", "iib", in);
  InsertRow(db, "INSERT INTO keypoints VALUES (2, ?1, ?2, ?3)", "iib", in);
  InsertRow(db, "INSERT INTO descriptors VALUES (1, ?1, ?2, ?3)", "iib", in);
  InsertRow(db, "INSERT INTO matches VALUES (2147483649, ?1, ?2, ?3)", "iib", in);
  InsertRow(
      db, "INSERT INTO two_view_geometries VALUES (2147483649, ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
      "iibibbbbb", in);
  InsertRow(db, "INSERT INTO portcal_housings VALUES (1, ?1, ?2)", "ib", in);
  InsertRow(db, "INSERT INTO portcal_unmasked_features VALUES (2, ?1, ?2, ?3)", "ibb", in);
  InsertRow(db, "INSERT INTO portcal_target_observations VALUES (1, ?1, ?2, ?3, ?4, ?5, ?6)",
            "iddddd", in);
  InsertRow(db,
            "INSERT INTO portcal_marker_detections VALUES (NULL, 1, 'DICT_4X4_50', ?1, ?2, ?3, ?4, "
            "?5, ?6, ?7, ?8, ?9)",
            "idddddddd", in);
  sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
}

template <typename F>
void Expect(F&& read) {
  try {
    read();
  } catch (const portcal::DatabaseError&) {
  } catch (const portcal::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = (portcal::fuzz::WorkFolder() / "blobs.db").string();
  static std::unique_ptr<portcal::Database> database =
      std::make_unique<portcal::Database>(path, portcal::Database::OpenMode::kCreate);
  static sqlite3* writer = [] {
    sqlite3* db = nullptr;
    if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) std::abort();
    sqlite3_exec(db, "PRAGMA synchronous=OFF", nullptr, nullptr, nullptr);
    return db;
  }();
  FieldReader in(data, size);
  Fill(writer, &in);
  portcal::Database& db = *database;
  Expect([&] { db.ReadCamera(1); });
  Expect([&] { db.ReadKeypoints(1); });
  Expect([&] { db.ReadDescriptors(1); });
  Expect([&] { db.ReadAllMatches(); });
  Expect([&] { db.ReadTwoViewGeometries(); });
  Expect([&] { db.ReadTwoViewGeometryNumInliers(); });
  Expect([&] { db.ReadAllHousings(); });
  Expect([&] {
    portcal::FeatureKeypoints keypoints;
    portcal::FeatureDescriptors descriptors;
    db.ReadUnmaskedFeatures(2, &keypoints, &descriptors);
  });
  Expect([&] { db.ReadMarkerDetections(1); });
  Expect([&] { portcal::ReadTargetViews(&db); });
  Expect([&] { portcal::SfmInputs::Read(&db); });
  return 0;
}
