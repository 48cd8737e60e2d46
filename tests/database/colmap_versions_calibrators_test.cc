// The calibrators on databases of COLMAP 3.8 to 4.1 (the fixtures of
// colmap_fixture.h: COLMAP's own rows and a table of the user's in each
// version's layout). target_extractor adds rendered boards' views to each
// version's fixture; then camera_calibrator, cross_check, pose_suggester,
// housing_calibrator (--update_database) and stereo_calibrator read them,
// and live_calibrator keeps frames of a rendered hand-held session in it.
// The auto-calibration stages extract, mask and match views of a marked
// 3-D target into each fixture; refractive_mapper and
// refractive_bundle_adjuster read them.
// Each result equals the one on a database portcal made itself (the same
// views in the same order: the same numbers), the stages that only read
// leave every table and the file's schema as they were, the writers leave
// COLMAP's rows and the user's table byte for byte and add their images as
// the version does (a frame in a rig of the camera's own from 3.12 on).
#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "colmap_ext/io/sparse_model.h"
#include "database/database.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/cross_check.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_masker.h"
#include "pipelines/stages/feature_matcher.h"
#include "pipelines/stages/housing_calibrator.h"
#include "pipelines/stages/live_calibrator.h"
#include "pipelines/stages/pose_suggester.h"
#include "pipelines/stages/refractive_bundle_adjuster.h"
#include "pipelines/stages/refractive_mapper.h"
#include "pipelines/stages/stereo_calibrator.h"
#include "tests/database/colmap_fixture.h"
#include "tests/pipelines/stages/live_test_setup.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::RawDatabase;

// The report page test's boards: RADIAL 480 x 360, six views, a board of
// `cols` x 6 corners of 25 mm (odd for the rig: see report_page_test).
fs::path BoardSet(const std::string& name, const std::string& housing_and_rig, int cols) {
  return testing::SharedRenderedImages("name: " + name + "\nseed: 7\nnum_images: 6\n" +
                                       "camera: {model: RADIAL, width: 480, height: 360, params: "
                                       "[400.0, 243.0, 178.0, -0.06, 0.01]}\n" +
                                       housing_and_rig +
                                       "target: {type: chessboard, cols: " + std::to_string(cols) +
                                       ", rows: 6, square_size: 0.025, margin: 0.015}\n" +
                                       "poses: {distance: [0.3, 0.6], tilt_max_deg: 40, "
                                       "roll_max_deg: 30}\nrender: {spp: 2, noise_sigma: 1.0}\n");
}

void Extract(const fs::path& images, const fs::path& database, bool per_folder, int cols) {
  testing::ExtractBoard(images, database, per_folder, "RADIAL", cols, 0.025);
}

// What each calibrator found.
struct CalibratorResults {
  std::vector<double> air_params;
  double cross_check_rms_px = 0;
  int cross_check_points = 0;
  std::vector<Eigen::Vector3d> suggested_positions;
  std::vector<double> housing_params, housed_camera_params;
  Eigen::Vector3d rig_translation = Eigen::Vector3d::Zero();
  Eigen::Vector4d rig_rotation = Eigen::Vector4d::Zero();
};

// The stages that only read, which must leave `database` as it was.
void ReadOnlyStages(const fs::path& dir, const fs::path& database, CalibratorResults* results) {
  RawDatabase before_db(database);
  const std::string before = before_db.DumpAll();
  CrossCheckOptions cross_check;
  cross_check.database_path = database.string();
  cross_check.input_calibration = (dir / "air" / "calibration.yaml").string();
  cross_check.output_path = (dir / "cross_check").string();
  const CrossCheckResult checked = RunCrossCheck(cross_check, NoProgress());
  results->cross_check_rms_px = checked.portcal_rms_px;
  results->cross_check_points = checked.num_points;
  PoseSuggesterOptions suggest;
  suggest.database_path = database.string();
  suggest.output_path = (dir / "suggested").string();
  suggest.target.chessboard.cols = 8;
  suggest.target.chessboard.rows = 6;
  suggest.target.square_size_m = 0.025;
  suggest.guidance.num_candidates = 50;
  suggest.num_poses = 2;
  for (const PoseSuggestion& pose : RunPoseSuggester(suggest, NoProgress()).poses) {
    results->suggested_positions.push_back(pose.cam_from_target.translation);
  }
  EXPECT_EQ(before_db.DumpAll(), before) << database;
}

// Every calibrator on the boards, each database the fixture of `version`
// (portcal's own without one).
CalibratorResults RunCalibrators(const fs::path& dir, std::optional<ColmapVersion> version) {
  std::map<std::string, std::string> colmap_rows;
  for (const std::string name : {"air", "dome", "rig"}) {
    if (version)
      colmap_rows[name] = testing::WriteFixtureAndSnapshot(dir / (name + ".db"), *version);
  }
  Extract(BoardSet("air", "housing: null\n", 8), dir / "air.db", false, 8);
  Extract(BoardSet("dome",
                   "housing: {model: DOMEPORT, params: [0.003, -0.002, 0.005, 0.05, 0.006, 1.0, "
                   "1.473, 1.334]}\n",
                   8),
          dir / "dome.db", false, 8);
  Extract(BoardSet("rig",
                   "housing: null\nstereo:\n  cam2_from_cam1: {rotation_axis_angle_deg: [0.0, 1.0, "
                   "0.0, -4.0], "
                   "translation: [-0.08, 0.0, 0.004]}\n",
                   9),
          dir / "rig.db", true, 9);
  CalibratorResults results;
  CameraCalibratorOptions camera;
  camera.database_path = (dir / "air.db").string();
  camera.output_path = (dir / "air").string();
  results.air_params = RunCameraCalibrator(camera, NoProgress()).camera.params;
  ReadOnlyStages(dir, dir / "air.db", &results);

  HousingCalibratorOptions housing;
  housing.database_path = (dir / "dome.db").string();
  housing.in_air_database_path = (dir / "air.db").string();
  housing.output_path = (dir / "dome").string();
  housing.housing =
      Housing::FromName("DOMEPORT", {0, 0, 0, 0.05, 0.006, 1.0, 1.473, 1.334}, "test");
  housing.update_database = true;
  const HousingCalibrationResult housed = RunHousingCalibrator(housing, NoProgress());
  results.housing_params = housed.housing.params;
  results.housed_camera_params = housed.camera.params;

  StereoCalibratorOptions rig;
  rig.database_path = (dir / "rig.db").string();
  rig.output_path = (dir / "rig").string();
  std::string rig_before;
  {
    RawDatabase db(dir / "rig.db");
    rig_before = db.DumpAll();
  }
  const StereoCalibrationResult stereo = RunStereoCalibrator(rig, NoProgress());
  results.rig_translation = stereo.cam2_from_cam1.translation;
  results.rig_rotation = stereo.cam2_from_cam1.rotation.coeffs();
  RawDatabase rig_db(dir / "rig.db");
  EXPECT_EQ(rig_db.DumpAll(), rig_before) << "stereo_calibrator changed the database";
  for (const auto& [name, rows] : colmap_rows) {
    RawDatabase db(dir / (name + ".db"));
    EXPECT_EQ(testing::ColmapRows(&db, LayoutOf(*version)), rows) << name;
    EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(*version)) << name;
  }
  return results;
}

void ExpectSame(const std::vector<double>& a, const std::vector<double>& b,
                const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_NEAR(a[i], b[i], 1e-9 * (1 + std::abs(b[i]))) << what << " " << i;
}

void ExpectSameResults(const CalibratorResults& results, const CalibratorResults& reference) {
  ExpectSame(results.air_params, reference.air_params, "camera_calibrator");
  EXPECT_NEAR(results.cross_check_rms_px, reference.cross_check_rms_px, 1e-9);
  EXPECT_EQ(results.cross_check_points, reference.cross_check_points);
  ASSERT_EQ(results.suggested_positions.size(), reference.suggested_positions.size());
  for (size_t i = 0; i < results.suggested_positions.size(); ++i) {
    EXPECT_LT((results.suggested_positions[i] - reference.suggested_positions[i]).norm(), 1e-9)
        << "suggestion " << i;
  }
  ExpectSame(results.housing_params, reference.housing_params, "housing_calibrator's housing");
  ExpectSame(results.housed_camera_params, reference.housed_camera_params,
             "housing_calibrator's camera");
  EXPECT_LT((results.rig_translation - reference.rig_translation).norm(), 1e-9);
  EXPECT_LT((results.rig_rotation - reference.rig_rotation).norm(), 1e-9);
}

// Every version in one test: the reference is computed once.
TEST(ColmapVersionsCalibrators, ReadEachVersionsLayoutAsPortcalsOwn) {
  testing::TempDir reference_dir;
  const CalibratorResults reference = RunCalibrators(reference_dir.path(), std::nullopt);
  for (const ColmapVersion version : AllColmapVersions()) {
    SCOPED_TRACE("COLMAP " + ColmapVersionName(version));
    testing::TempDir dir;
    ExpectSameResults(RunCalibrators(dir.path(), version), reference);
    // housing_calibrator --update_database wrote the dome into the board's
    // camera (after COLMAP's two), its intrinsics into that camera's row.
    RawDatabase dome(dir / "dome.db");
    EXPECT_EQ(dome.Int("SELECT count(*) FROM images;"), 8);
    EXPECT_EQ(dome.Dump("SELECT camera_id, model FROM portcal_housings;"),
              "3|1|\n");  // 1: DOMEPORT
  }
}

// Frames kept by the live calibrator become images of the version's kind.
TEST(ColmapVersionsCalibrators, LiveCalibratorKeepsFramesAsEachVersionDoes) {
  const fs::path frames = testing::SharedRenderedImages(testing::LiveTrajectoryYaml(11, 2, false));
  for (const ColmapVersion version : AllColmapVersions()) {
    SCOPED_TRACE("COLMAP " + ColmapVersionName(version));
    const ColmapLayout layout = LayoutOf(version);
    testing::TempDir dir;
    LiveCalibratorOptions options = testing::LiveOptions(dir, frames.string());
    const std::string before = testing::WriteFixtureAndSnapshot(options.database_path, version);
    options.live.source.realtime = false;
    options.calibrate_at_end = false;
    EXPECT_EQ(RunLiveCalibrator(options, NoProgress()).session.kept, 2);
    RawDatabase db(options.database_path);
    EXPECT_EQ(testing::ColmapRows(&db, layout), before);
    EXPECT_EQ(db.Int("PRAGMA user_version;"), ColmapUserVersion(version));
    EXPECT_EQ(db.Int("SELECT count(*) FROM images;"), 4);
    EXPECT_EQ(db.Int("SELECT count(DISTINCT image_id) FROM portcal_target_observations;"), 2);
    if (layout.rigs_and_frames) {
      // Each kept image in a frame of its own, in the rig whose reference
      // sensor is its camera.
      EXPECT_EQ(db.Int("SELECT count(*) FROM images JOIN frame_data ON data_id = image_id AND "
                       "sensor_type = 0 AND "
                       "sensor_id = camera_id JOIN frames USING(frame_id) JOIN rigs USING(rig_id) "
                       "WHERE image_id > 2 "
                       "AND ref_sensor_id = camera_id;"),
                2);
    }
  }
}

// Views of the two-face ArUco target behind a flat port for the
// auto-calibration stages.
fs::path MarkedTargetSet() {
  return testing::SharedRenderedImages(
      std::string("name: versions_mapping\nnum_images: 6\nseed: 5\n") +
      "camera: {model: SIMPLE_RADIAL, width: 640, height: 360, params: [500.0, 320.0, 180.0, "
      "-0.02]}\n"
      "housing: {model: FLATPORT, params: [0.0174524, 0.0, 0.9998477, 0.01, 0.008, 1.0, 1.473, "
      "1.334]}\n" +
      testing::kTwoFaceTargetYaml +
      "poses: {distance: [0.45, 0.9], tilt_max_deg: 35, roll_max_deg: 60, visibility: markers, "
      "border_margin_px: 10, max_view_angle_deg: 60}\n"
      "render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}\n");
}

// What the mapper and the adjustment made: each image's centre by name,
// the points, the camera and its port.
struct MappedScene {
  std::map<std::string, Eigen::Vector3d> centres;
  size_t num_points = 0;
  std::vector<double> camera_params, housing_params;
};

MappedScene MapAndRefine(const fs::path& dir, std::optional<ColmapVersion> version) {
  const fs::path database = dir / "db.db";
  std::string colmap_rows;
  if (version) colmap_rows = testing::WriteFixtureAndSnapshot(database, *version);
  FeatureExtractorOptions extract;
  extract.database_path = database.string();
  extract.image_path = MarkedTargetSet().string();
  extract.reader.single_camera = true;
  RunFeatureExtractor(extract, NoProgress());
  // The masker reads every image of the database: COLMAP's a.png and
  // b.png (without markers) beside the target's views.
  fs::create_directories(dir / "images");
  for (const auto& entry : fs::directory_iterator(MarkedTargetSet())) {
    fs::copy_file(entry.path(), dir / "images" / entry.path().filename());
  }
  for (const std::string name : {"a.png", "b.png"}) {
    cv::imwrite((dir / "images" / name).string(), testing::ClutteredScene(320, 240, name[0]));
  }
  FeatureMaskerOptions mask;
  mask.database_path = database.string();
  mask.image_path = (dir / "images").string();
  RunFeatureMasker(mask, NoProgress());
  FeatureMatcherOptions match;
  match.database_path = database.string();
  match.mode = PairingMode::kExhaustive;
  RunFeatureMatcher(match, NoProgress());
  RawDatabase db(database);
  const std::string before = db.DumpAll();
  RefractiveMapperOptions map;
  map.database_path = database.string();
  map.output_path = (dir / "sparse").string();
  map.mapper.marker_scale.side_length_m = 0.06;
  // One thread: two threads sum in either order, and the models of one
  // database differ by micrometres from run to run.
  map.mapper.num_threads = 1;
  map.housing = Housing::FromName("FLATPORT", {0, 0, 1, 0.01, 0.008, 1.0, 1.473, 1.334}, "test");
  const RefractiveMapperSummary mapped = RunRefractiveMapper(map, NoProgress());
  EXPECT_EQ(mapped.num_models, 1);
  RefractiveBundleAdjusterOptions refine;
  refine.input_path = mapped.model_paths.at(0).string();
  refine.output_path = (dir / "refined").string();
  refine.database_path = database.string();
  refine.marker_scale.side_length_m = 0.06;  // the markers' corners, read from the database
  refine.ba.refine_housing = false;          // what it reads, not a self-calibration (seconds)
  refine.ba.num_threads = 1;
  RunRefractiveBundleAdjuster(refine, NoProgress());
  EXPECT_EQ(db.DumpAll(), before) << "the mapper or the adjustment changed the database";
  if (version) {
    EXPECT_EQ(testing::ColmapRows(&db, LayoutOf(*version)), colmap_rows);
    // --ImageReader.single_camera: the views share a camera of their size,
    // COLMAP's 320 x 240 images keep theirs.
    EXPECT_EQ(db.Int("SELECT count(DISTINCT camera_id) FROM images WHERE name LIKE 'img_%';"), 1);
    EXPECT_EQ(db.Int("SELECT min(camera_id) FROM images WHERE name LIKE 'img_%';"), 3);
  }
  const SparseModel model = ReadSparseModel(dir / "refined");
  MappedScene scene;
  for (const auto& [id, image] : model.images) {
    scene.centres[image.name] = image.cam_from_world.Inverse().translation;
  }
  scene.num_points = model.points3D.size();
  EXPECT_EQ(model.cameras.size(), 1u);
  if (!model.cameras.empty()) scene.camera_params = model.cameras.begin()->second.params;
  if (!model.housings.empty()) scene.housing_params = model.housings.begin()->second.params;
  return scene;
}

TEST(ColmapVersionsCalibrators, MapperAndAdjustmentReadEachVersionsLayoutAsPortcalsOwn) {
  testing::TempDir reference_dir;
  const MappedScene reference = MapAndRefine(reference_dir.path(), std::nullopt);
  ASSERT_EQ(reference.centres.size(), 6u);
  ASSERT_EQ(reference.housing_params.size(), 8u);
  for (const ColmapVersion version : AllColmapVersions()) {
    SCOPED_TRACE("COLMAP " + ColmapVersionName(version));
    testing::TempDir dir;
    const MappedScene scene = MapAndRefine(dir.path(), version);
    EXPECT_EQ(scene.num_points, reference.num_points);
    ExpectSame(scene.camera_params, reference.camera_params, "the refined camera");
    ExpectSame(scene.housing_params, reference.housing_params, "the port");
    ASSERT_EQ(scene.centres.size(), reference.centres.size());
    for (const auto& [name, centre] : reference.centres) {
      ASSERT_EQ(scene.centres.count(name), 1u) << name;
      EXPECT_LT((scene.centres.at(name) - centre).norm(), 1e-9) << name;
    }
  }
}

}  // namespace
}  // namespace portcal
