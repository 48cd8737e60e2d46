#include "tests/database/colmap_fixture.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "database/schema.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal::testing {

RawDatabase::RawDatabase(const fs::path& path) {
  EXPECT_EQ(sqlite3_open(path.c_str(), &db_), SQLITE_OK);
}

RawDatabase::~RawDatabase() { sqlite3_close(db_); }

void RawDatabase::Exec(const std::string& sql) {
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << sql << ": " << error;
}

std::string RawDatabase::Dump(const std::string& query) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db_, query.c_str(), -1, &stmt, nullptr) != SQLITE_OK)
    return "error: " + query;
  std::string out;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
      if (sqlite3_column_type(stmt, c) == SQLITE_BLOB) {
        out +=
            Hex(sqlite3_column_blob(stmt, c), static_cast<size_t>(sqlite3_column_bytes(stmt, c)));
      } else if (sqlite3_column_type(stmt, c) == SQLITE_NULL) {
        out += "NULL";
      } else {
        out += reinterpret_cast<const char*>(sqlite3_column_text(stmt, c));
      }
      out += "|";
    }
    out += "\n";
  }
  sqlite3_finalize(stmt);
  return out;
}

int64_t RawDatabase::Int(const std::string& query) {
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(db_, query.c_str(), -1, &stmt, nullptr);
  const int64_t value = sqlite3_step(stmt) == SQLITE_ROW ? sqlite3_column_int64(stmt, 0) : -1;
  sqlite3_finalize(stmt);
  return value;
}

std::string RawDatabase::DumpAll() {
  std::string out = Dump("SELECT type, name, sql FROM sqlite_master ORDER BY name;");
  const std::string tables =
      Dump("SELECT name FROM sqlite_master WHERE type='table' ORDER BY name;");
  size_t start = 0;
  for (size_t end = tables.find("|\n"); end != std::string::npos; end = tables.find("|\n", start)) {
    const std::string table = tables.substr(start, end - start);
    out += table + ":\n" + Dump("SELECT * FROM \"" + table + "\";");
    start = end + 2;
  }
  return out + "user_version " + std::to_string(Int("PRAGMA user_version;"));
}

std::string Hex(const void* data, size_t size) {
  static const char* const kHex = "0123456789abcdef";
  std::string out = "x'";
  for (size_t i = 0; i < size; ++i) {
    const unsigned char byte = static_cast<const unsigned char*>(data)[i];
    out += kHex[byte >> 4];
    out += kHex[byte & 15];
  }
  return out + "'";
}

std::string DoublesHex(std::initializer_list<double> values) {
  std::vector<double> v(values);
  return Hex(v.data(), v.size() * sizeof(double));
}

void WriteFixture(const fs::path& path, ColmapVersion version) {
  RawDatabase db(path);
  for (const std::string& sql : ColmapSchemaSql(version)) db.Exec(sql + ";");
  db.Exec("PRAGMA user_version = " + std::to_string(ColmapUserVersion(version)) + ";");
  const ColmapLayout layout = LayoutOf(version);
  const std::string params = DoublesHex({384, 160, 120, 0});
  for (int id : {1, 2}) {
    const std::string name = id == 1 ? "a.png" : "b.png";
    db.Exec("INSERT INTO cameras VALUES(" + std::to_string(id) + ", 2, 320, 240, " + params +
            ", 0);");
    if (layout.image_prior_columns) {
      db.Exec("INSERT INTO images VALUES(" + std::to_string(id) + ", '" + name + "', " +
              std::to_string(id) +
              (id == 1 ? ", NULL, NULL, NULL, NULL, 47.1, 8.5, 420.0);"
                       : ", NULL, NULL, NULL, NULL, NULL, NULL, NULL);"));
    } else {
      db.Exec("INSERT INTO images VALUES(" + std::to_string(id) + ", '" + name + "', " +
              std::to_string(id) + ");");
    }
    if (layout.rigs_and_frames) {
      db.Exec("INSERT INTO rigs VALUES(" + std::to_string(id) + ", " + std::to_string(id) +
              ", 0);");
      db.Exec("INSERT INTO frames VALUES(" + std::to_string(id) + ", " + std::to_string(id) + ");");
      db.Exec("INSERT INTO frame_data VALUES(" + std::to_string(id) + ", " + std::to_string(id) +
              ", " + std::to_string(id) + ", 0);");
    }
  }
  const std::string gps = DoublesHex({47.1, 8.5, 420.0});
  const double nan = std::nan("");
  const std::string nan9 = DoublesHex({nan, nan, nan, nan, nan, nan, nan, nan, nan});
  if (layout.pose_priors == ColmapLayout::PosePriors::kPerImage) {
    db.Exec("INSERT INTO pose_priors VALUES(1, " + gps + ", 0" +
            (layout.pose_prior_covariance ? ", " + nan9 : "") + ");");
  } else if (layout.pose_priors == ColmapLayout::PosePriors::kPerData) {
    db.Exec("INSERT INTO pose_priors VALUES(1, 1, 1, 0, " + gps + ", " + nan9 + ", " +
            DoublesHex({nan, nan, nan}) + ", 0);");
  }
  db.Exec("CREATE TABLE user_notes(note TEXT); INSERT INTO user_notes VALUES('keep me');");
}

std::string ColmapRows(RawDatabase* db, const ColmapLayout& layout) {
  std::string rows = db->Dump("SELECT * FROM user_notes;") +
                     db->Dump("SELECT * FROM cameras WHERE camera_id <= 2;") +
                     db->Dump("SELECT image_id, name, camera_id FROM images WHERE image_id <= 2;");
  if (layout.rigs_and_frames) {
    rows += db->Dump("SELECT * FROM rigs WHERE rig_id <= 2;") +
            db->Dump("SELECT * FROM frames WHERE frame_id <= 2;") +
            db->Dump("SELECT * FROM frame_data WHERE frame_id <= 2;") +
            db->Dump("SELECT * FROM rig_sensors;");
  }
  return rows;
}

std::string WriteFixtureAndSnapshot(const fs::path& path, ColmapVersion version) {
  WriteFixture(path, version);
  RawDatabase db(path);
  return ColmapRows(&db, LayoutOf(version));
}

fs::path SharedRenderedImages(const std::string& config_yaml) {
  static std::map<std::string, std::unique_ptr<TempDir>> sets;
  std::unique_ptr<TempDir>& dir = sets[config_yaml];
  if (!dir) {
    dir = std::make_unique<TempDir>();
    RenderSet(*dir, config_yaml);
  }
  return dir->path() / "set" / "images";
}

std::string VersionTestName(ColmapVersion version) {
  std::string name = "COLMAP_" + ColmapVersionName(version);
  std::replace(name.begin(), name.end(), '.', '_');
  return name;
}

}  // namespace portcal::testing
