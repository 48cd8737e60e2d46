// What the per-version tests of COLMAP's databases share: each version's
// fixture (that version's CREATE statements from colmap_schemas.cc, filled
// with raw SQL the way that version's writer fills it), a raw view of a
// database for comparing rows byte for byte, and rendered sets shared by a
// test program's cases.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>

#include "database/colmap_layout.h"

namespace portcal::testing {

// A database as SQL sees it, without portcal's layer.
class RawDatabase {
 public:
  explicit RawDatabase(const std::filesystem::path& path);
  ~RawDatabase();
  RawDatabase(const RawDatabase&) = delete;
  RawDatabase& operator=(const RawDatabase&) = delete;
  void Exec(const std::string& sql);
  // Every row of `query`, values as text (blobs in hex), one line per row.
  std::string Dump(const std::string& query);
  // The first column of the first row (-1 without a row).
  int64_t Int(const std::string& query);
  // Every table's schema and rows.
  std::string DumpAll();

 private:
  sqlite3* db_ = nullptr;
};

std::string Hex(const void* data, size_t size);  // x'0a1b...'
std::string DoublesHex(std::initializer_list<double> values);

// A database as COLMAP `version` leaves it after importing a.png and b.png
// (320 x 240, one SIMPLE_RADIAL camera each, COLMAP's default parameters),
// a.png with a GPS prior, plus the user's own table user_notes.
void WriteFixture(const std::filesystem::path& path, ColmapVersion version);

// What COLMAP wrote in the fixture, which portcal's stages must leave as it
// was.
std::string ColmapRows(RawDatabase* db, const ColmapLayout& layout);

// The fixture of `version` at `path`, and what COLMAP wrote in it.
std::string WriteFixtureAndSnapshot(const std::filesystem::path& path, ColmapVersion version);

// The images of a set rendered once from `config_yaml` and shared by the
// program's tests (the folder removed at exit).
std::filesystem::path SharedRenderedImages(const std::string& config_yaml);

// "COLMAP_3_8": a test name for a version.
std::string VersionTestName(ColmapVersion version);

}  // namespace portcal::testing
