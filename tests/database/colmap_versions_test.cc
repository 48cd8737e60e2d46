// Databases of COLMAP 3.8 to 4.1. Each version's fixture is made from that
// version's CREATE statements (colmap_schemas.cc: extracted from COLMAP's
// sources at the tags it cites) and filled with raw SQL the way that
// version's writer fills it: two images with their own cameras, a pose
// prior where the version keeps one (a WGS84 one), a rig per camera and a
// frame per image from 3.12 on, and a table of the user's. portcal's
// feature_extractor (a third image), pose_prior_importer, the spatial,
// sequential and exhaustive matchers, and target_extractor,
// camera_calibrator (--update_database) and calibration_evaluator on a
// rendered chessboard set, and feature_extractor and feature_masker on a
// rendered ArUco target, then run on it; the user's table and COLMAP's rows
// stay byte for byte, and the rows portcal adds follow the version's
// conventions. Conversions between layouts keep every row; what a target
// cannot hold is refused with nothing changed; a newer COLMAP is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "database/schema.h"
#include "pipelines/stages/calibration_evaluator.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/database_converter.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_masker.h"
#include "pipelines/stages/feature_matcher.h"
#include "pipelines/stages/pose_prior_importer.h"
#include "tests/database/colmap_fixture.h"
#include "tests/pipelines/stages/live_test_setup.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::ColmapRows;
using testing::DoublesHex;
using testing::Hex;
using testing::RawDatabase;
using testing::SharedRenderedImages;
using testing::WriteFixture;
using testing::WriteFixtureAndSnapshot;

// Three overlapping views of one cluttered scene, 320 x 240.
void WriteImages(const fs::path& dir) {
  fs::create_directories(dir);
  const cv::Mat scene = testing::ClutteredScene(400, 240, 29);
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((dir / (std::string(1, static_cast<char>('a' + i)) + ".png")).string(),
                scene(cv::Rect(40 * i, 0, 320, 240)));
  }
}

void RunStages(const fs::path& dir, const fs::path& database) {
  FeatureExtractorOptions extract;
  extract.database_path = database.string();
  extract.image_path = (dir / "images").string();
  extract.num_threads = 1;
  EXPECT_EQ(RunFeatureExtractor(extract, NoProgress()).num_extracted, 3);
  std::ofstream(dir / "positions.txt") << "a.png 0 0 2\nb.png 0.1 0 2\nc.png 0.2 0 2\n";
  PosePriorImporterOptions priors;
  priors.database_path = database.string();
  priors.input_path = (dir / "positions.txt").string();
  EXPECT_EQ(RunPosePriorImporter(priors, NoProgress()).num_imported, 3);
  FeatureMatcherOptions match;
  match.database_path = database.string();
  match.num_threads = 1;
  // The spatial (by the priors) and sequential matchers, then the
  // exhaustive one, each matching again.
  match.mode = PairingMode::kSpatial;
  EXPECT_GT(RunFeatureMatcher(match, NoProgress()).num_pairs, 0);
  match.overwrite = true;
  match.mode = PairingMode::kSequential;
  EXPECT_GT(RunFeatureMatcher(match, NoProgress()).num_pairs, 0);
  match.mode = PairingMode::kExhaustive;
  EXPECT_EQ(RunFeatureMatcher(match, NoProgress()).num_pairs, 3);
}

// The rows portcal added, checked against `layout`'s conventions.
void ExpectConventions(RawDatabase* db, const ColmapLayout& layout, const std::string& version) {
  const int64_t c = db->Int("SELECT image_id FROM images WHERE name='c.png';");
  const int64_t camera = db->Int("SELECT camera_id FROM images WHERE name='c.png';");
  ASSERT_GT(c, 2) << version;
  if (layout.rigs_and_frames) {
    // One frame of its own, in the rig whose reference is its camera.
    EXPECT_EQ(db->Int("SELECT count(*) FROM frame_data WHERE data_id=" + std::to_string(c) +
                      " AND sensor_type=0 AND "
                      "sensor_id=" +
                      std::to_string(camera) + ";"),
              1)
        << version;
    EXPECT_EQ(db->Int("SELECT count(*) FROM frames JOIN frame_data USING(frame_id) JOIN rigs "
                      "USING(rig_id) WHERE "
                      "data_id=" +
                      std::to_string(c) + " AND ref_sensor_id=" + std::to_string(camera) + ";"),
              1)
        << version;
    EXPECT_EQ(db->Int("SELECT count(*) FROM rigs;"), 3) << version;
  }
  if (layout.descriptor_type) {
    EXPECT_EQ(db->Int("SELECT count(*) FROM descriptors WHERE type=0;"), 3) << version;
  }
  const std::string position_c = DoublesHex({0.2, 0, 2});
  switch (layout.pose_priors) {
    case ColmapLayout::PosePriors::kNone:
      EXPECT_EQ(
          db->Dump("SELECT prior_qw, prior_tx, prior_ty, prior_tz FROM images WHERE name='c.png';"),
          "NULL|0.2|0.0|2.0|\n")
          << version;
      break;
    case ColmapLayout::PosePriors::kPerImage:
      EXPECT_EQ(db->Dump("SELECT position, coordinate_system FROM pose_priors WHERE image_id=" +
                         std::to_string(c) + ";"),
                position_c + "|1|\n")
          << version;
      break;
    default:
      EXPECT_EQ(db->Dump("SELECT corr_sensor_id, corr_sensor_type, position, coordinate_system "
                         "FROM pose_priors "
                         "WHERE corr_data_id=" +
                         std::to_string(c) + ";"),
                std::to_string(camera) + "|0|" + position_c + "|1|\n")
          << version;
  }
  // Two-view geometries: COLMAP 4 leaves NULL what was not estimated, 3.x
  // writes zeros; neither writes both forms.
  const int64_t nulls = db->Int(
      "SELECT count(*) FROM two_view_geometries WHERE F IS NULL OR E IS NULL OR qvec IS NULL;");
  const int64_t zeros = db->Int(
      "SELECT count(*) FROM two_view_geometries WHERE rows > 0 AND (E = zeroblob(72) OR "
      "F = zeroblob(72) OR H = zeroblob(72));");
  EXPECT_EQ(db->Int("SELECT count(*) FROM two_view_geometries;"), 3) << version;
  if (layout.NullForUnset()) {
    EXPECT_EQ(zeros, 0) << version;
  } else {
    EXPECT_EQ(nulls, 0) << version;
  }
}

class ColmapVersions : public ::testing::TestWithParam<ColmapVersion> {};

TEST_P(ColmapVersions, StagesKeepColmapsRowsAndWriteAsTheVersionDoes) {
  const ColmapVersion version = GetParam();
  const std::string name = ColmapVersionName(version);
  testing::TempDir dir;
  WriteImages(dir / "images");
  const fs::path database = dir / "colmap.db";
  const ColmapLayout layout = LayoutOf(version);
  const std::string before = WriteFixtureAndSnapshot(database, version);
  RunStages(dir.path(), database);
  RawDatabase db(database);
  EXPECT_EQ(ColmapRows(&db, layout), before) << name;
  EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(version)) << name;
  ExpectConventions(&db, layout, name);
  Database reopened(database, Database::OpenMode::kReadOnly);
  EXPECT_EQ(reopened.layout().VersionRange(), LayoutOf(version).VersionRange());
  EXPECT_EQ(reopened.ReadAllImages().size(), 3u);
  EXPECT_TRUE(reopened.ReadAllImages()[2].PriorPosition().has_value());
}

// A chessboard set for the calibration stages.
fs::path ChessboardSet() {
  return SharedRenderedImages(R"(name: versions
seed: 29
num_images: 6
camera: {model: OPENCV, width: 480, height: 360, params: [380, 378, 243.5, 177.0, -0.2, 0.05, 0.001, -0.0005]}
housing: null
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.35, 0.7], tilt_max_deg: 40, roll_max_deg: 20, border_margin_px: 10}
render: {spp: 1, noise_sigma: 1.0}
)");
}

TEST_P(ColmapVersions, CalibrationStagesKeepColmapsRowsAndWriteAsTheVersionDoes) {
  const ColmapVersion version = GetParam();
  const std::string name = ColmapVersionName(version);
  testing::TempDir dir;
  const fs::path database = dir / "colmap.db";
  const ColmapLayout layout = LayoutOf(version);
  const std::string before = WriteFixtureAndSnapshot(database, version);
  testing::ExtractBoard(ChessboardSet(), database, false);
  CameraCalibratorOptions calibrate;
  calibrate.database_path = database.string();
  calibrate.output_path = (dir / "cal").string();
  calibrate.update_database = true;
  RunCameraCalibrator(calibrate, NoProgress());
  CalibrationEvaluatorOptions evaluate;
  evaluate.database_path = database.string();
  evaluate.input_calibration = (dir / "cal" / "calibration.yaml").string();
  evaluate.output_path = (dir / "evaluation").string();
  EXPECT_EQ(RunCalibrationEvaluator(evaluate, NoProgress()).evaluation.views.size(), 6u) << name;
  RawDatabase db(database);
  EXPECT_EQ(ColmapRows(&db, layout), before) << name;
  EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(version)) << name;
  EXPECT_EQ(db.Int("SELECT count(*) FROM images;"), 8) << name;
  // The calibration went into the board's camera, an OPENCV one of its own.
  const int64_t camera = db.Int("SELECT camera_id FROM images WHERE image_id = 3;");
  EXPECT_EQ(db.Int("SELECT model FROM cameras WHERE camera_id = " + std::to_string(camera) + ";"),
            4)
      << name;
  if (layout.rigs_and_frames) {
    EXPECT_EQ(db.Int("SELECT count(*) FROM frame_data JOIN frames USING(frame_id) JOIN rigs "
                     "USING(rig_id) WHERE "
                     "ref_sensor_id = " +
                     std::to_string(camera) + " AND sensor_id = " + std::to_string(camera) + ";"),
              6)
        << name;
    EXPECT_EQ(db.Int("SELECT count(*) FROM rigs;"), 3) << name;
  }
  Database reopened(database, Database::OpenMode::kReadOnly);
  EXPECT_EQ(reopened.ReadTargetObservations(3).size(), 54u) << name;
}

// Three views of the two-face ArUco target for feature_masker.
fs::path MarkerSet() {
  return SharedRenderedImages(
      std::string("name: versions_markers\nnum_images: 3\nseed: 3\n") +
      "camera: {model: RADIAL, width: 480, height: 270, params: [330.0, 240.0, 135.0, 0, "
      "0]}\nhousing: null\n" +
      testing::kTwoFaceTargetYaml +
      "poses: {distance: [0.4, 0.7], tilt_max_deg: 30, roll_max_deg: 30, visibility: markers}\n"
      "render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}\n");
}

TEST_P(ColmapVersions, FeatureMaskerKeepsColmapsRowsAndWritesAsTheVersionDoes) {
  const ColmapVersion version = GetParam();
  const std::string name = ColmapVersionName(version);
  testing::TempDir dir;
  const fs::path database = dir / "colmap.db";
  const ColmapLayout layout = LayoutOf(version);
  const std::string before = WriteFixtureAndSnapshot(database, version);
  // COLMAP's a.png and b.png (no markers) beside the target's views.
  WriteImages(dir / "images");
  fs::remove(dir / "images" / "c.png");
  for (const auto& entry : fs::directory_iterator(MarkerSet())) {
    fs::copy_file(entry.path(), dir / "images" / entry.path().filename());
  }
  FeatureExtractorOptions extract;
  extract.database_path = database.string();
  extract.image_path = (dir / "images").string();
  RunFeatureExtractor(extract, NoProgress());
  FeatureMaskerOptions mask;
  mask.database_path = database.string();
  mask.image_path = extract.image_path;
  const FeatureMaskerSummary masked = RunFeatureMasker(mask, NoProgress());
  EXPECT_LT(masked.num_features_kept, masked.num_features_before) << name;
  RawDatabase db(database);
  EXPECT_EQ(ColmapRows(&db, layout), before) << name;
  EXPECT_GE(db.Int("SELECT count(*) FROM portcal_unmasked_features;"), 3) << name;
  EXPECT_EQ(db.Int("SELECT sum(rows) FROM descriptors;"), masked.num_features_kept) << name;
  if (layout.descriptor_type) {
    EXPECT_EQ(db.Int("SELECT count(*) FROM descriptors WHERE type = 0;"), 5) << name;
  }
  if (layout.rigs_and_frames) {
    EXPECT_EQ(db.Int("SELECT count(*) FROM frame_data;"), 5) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(AllVersions, ColmapVersions, ::testing::ValuesIn(AllColmapVersions()),
                         [](const ::testing::TestParamInfo<ColmapVersion>& info) {
                           return testing::VersionTestName(info.param);
                         });

// Every table's rows, in a form two layouts can be compared by: images
// with their priors as portcal reads them.
std::string Content(const fs::path& path) {
  RawDatabase db(path);
  std::string content =
      db.Dump("SELECT * FROM cameras;") + db.Dump("SELECT * FROM keypoints;") +
      db.Dump("SELECT image_id, rows, cols, data FROM descriptors;") +
      db.Dump("SELECT * FROM matches;") + db.Dump("SELECT * FROM user_notes;") +
      db.Dump("SELECT pair_id, rows, cols, data, config FROM two_view_geometries;");
  Database database(path, Database::OpenMode::kReadOnly);
  for (const DatabaseImage& image : database.ReadAllImages()) {
    content +=
        std::to_string(image.image_id) + " " + image.name + " " + std::to_string(image.camera_id);
    if (const auto position = image.PriorPosition()) {
      content += " " + Hex(position->data(), 24);
    }
    content += "\n";
  }
  return content;
}

TEST(ColmapVersionConversion, ThreeEightToFourOneAndBackKeepsEveryRow) {
  testing::TempDir dir;
  WriteImages(dir / "images");
  const fs::path database = dir / "colmap.db";
  WriteFixture(database, ColmapVersion::k3_8);
  RunStages(dir.path(), database);
  std::string original;
  {
    RawDatabase db(database);
    original = db.Dump("SELECT * FROM cameras;") + db.Dump("SELECT * FROM images;") +
               db.Dump("SELECT * FROM keypoints;") + db.Dump("SELECT * FROM descriptors;") +
               db.Dump("SELECT * FROM matches;") + db.Dump("SELECT * FROM two_view_geometries;") +
               db.Dump("SELECT * FROM user_notes;");
  }
  const std::string content = Content(database);
  for (const ColmapVersion via : AllColmapVersions()) {
    DatabaseConverterOptions up;
    up.database_path = database.string();
    up.output_path = (dir / ("via_" + ColmapVersionName(via) + ".db")).string();
    up.colmap_version = via;
    RunDatabaseConverter(up, NoProgress());
    // The same rows, read where the version keeps them.
    EXPECT_EQ(Content(up.output_path), content) << ColmapVersionName(via);
    {
      RawDatabase db(up.output_path);
      EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(via));
      if (LayoutOf(via).rigs_and_frames) {
        EXPECT_EQ(db.Int("SELECT count(*) FROM frame_data;"), 3);
        EXPECT_EQ(db.Int("SELECT count(*) FROM rigs;"), db.Int("SELECT count(*) FROM cameras;"));
      }
      if (LayoutOf(via).NullForUnset()) {
        EXPECT_EQ(db.Int("SELECT count(*) FROM two_view_geometries WHERE E = zeroblob(72) OR F = "
                         "zeroblob(72) OR "
                         "H = zeroblob(72) OR length(F) = 0;"),
                  0);
      }
    }
    DatabaseConverterOptions down;
    down.database_path = up.output_path;
    down.colmap_version = ColmapVersion::k3_8;
    RunDatabaseConverter(down, NoProgress());
    RawDatabase back(up.output_path);
    const std::string round_trip =
        back.Dump("SELECT * FROM cameras;") + back.Dump("SELECT * FROM images;") +
        back.Dump("SELECT * FROM keypoints;") + back.Dump("SELECT * FROM descriptors;") +
        back.Dump("SELECT * FROM matches;") + back.Dump("SELECT * FROM two_view_geometries;") +
        back.Dump("SELECT * FROM user_notes;");
    EXPECT_EQ(round_trip, original) << "3.8 -> " << ColmapVersionName(via) << " -> 3.8";
    EXPECT_EQ(
        back.Int(
            "SELECT count(*) FROM sqlite_master WHERE name IN ('rigs', 'frames', 'pose_priors');"),
        0);
  }
}

// Refusals leave the file as it was.
void ExpectRefusal(const fs::path& path, ColmapVersion target, const std::string& words) {
  { Database open(path); }  // portcal's tables added, as on any first open
  std::string before;
  {
    RawDatabase db(path);
    before = db.Dump("SELECT name, sql FROM sqlite_master ORDER BY name;") +
             db.Dump("SELECT * FROM descriptors;");
  }
  try {
    Database database(path);
    database.ConvertTo(target);
    ADD_FAILURE() << "converted; expected a refusal naming " << words;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
  RawDatabase db(path);
  EXPECT_EQ(db.Dump("SELECT name, sql FROM sqlite_master ORDER BY name;") +
                db.Dump("SELECT * FROM descriptors;"),
            before);
}

TEST(ColmapVersionConversion, WhatThreeXCannotHoldIsRefused) {
  testing::TempDir dir;
  // A rig of two cameras (camera 2 a sensor of camera 1's rig).
  WriteFixture(dir / "rig.db", ColmapVersion::k4_1);
  {
    RawDatabase db(dir / "rig.db");
    db.Exec("DELETE FROM rigs WHERE rig_id=2; INSERT INTO rig_sensors VALUES(1, 2, 0, NULL);");
  }
  ExpectRefusal(dir / "rig.db", ColmapVersion::k3_11, "rig sensors");
  // A rig on an IMU without frames yet.
  WriteFixture(dir / "imu.db", ColmapVersion::k3_12);
  {
    RawDatabase db(dir / "imu.db");
    db.Exec("INSERT INTO rigs VALUES(3, 1, 1);");  // reference sensor 1 of type IMU
  }
  ExpectRefusal(dir / "imu.db", ColmapVersion::k3_10,
                "1 rigs whose reference sensor is not a camera");
  // ALIKED descriptors.
  WriteFixture(dir / "aliked.db", ColmapVersion::k4_1);
  {
    RawDatabase db(dir / "aliked.db");
    db.Exec("INSERT INTO descriptors VALUES(1, 1, 0, 128, NULL);");
  }
  ExpectRefusal(dir / "aliked.db", ColmapVersion::k3_13, "other than SIFT");
  Database aliked(dir / "aliked.db", Database::OpenMode::kReadOnly);
  EXPECT_THROW(aliked.ReadDescriptors(1), DatabaseError);
  // A prior with a gravity direction.
  WriteFixture(dir / "gravity.db", ColmapVersion::k4_0);
  {
    RawDatabase db(dir / "gravity.db");
    db.Exec("UPDATE pose_priors SET gravity=" + DoublesHex({0, 1, 0}) + ";");
  }
  ExpectRefusal(dir / "gravity.db", ColmapVersion::k3_12, "gravity");
}

TEST(ColmapVersionConversion, CreatorMakesEachVersionsLayout) {
  testing::TempDir dir;
  for (const ColmapVersion version : AllColmapVersions()) {
    const fs::path path = dir / ("v" + ColmapVersionName(version) + ".db");
    { Database created(path, Database::OpenMode::kCreate, version); }
    RawDatabase db(path);
    EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(version));
    // The very statements COLMAP runs (sqlite_master keeps them without
    // "IF NOT EXISTS").
    for (const std::string& sql : ColmapSchemaSql(version)) {
      std::string stored = sql;
      stored.erase(stored.find(" IF NOT EXISTS"), 14);
      EXPECT_EQ(db.Int("SELECT count(*) FROM sqlite_master WHERE sql='" + stored + "';"), 1)
          << stored;
    }
  }
}

}  // namespace
}  // namespace portcal
