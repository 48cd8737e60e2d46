// The auto-calibration stages against the real `colmap` 3.8 binary:
//  - features extracted and matched by portcal are reconstructed by
//    `colmap mapper`;
//  - a database extracted by `colmap feature_extractor` goes through
//    portcal's masker, matcher and refractive mapper, and `colmap
//    model_converter` reads portcal's model;
// and the stages' database safety: a rerun skips finished work, a failed
// stage leaves the file byte for byte as it was.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/sparse_model.h"
#include "database/database.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::RunCommand;

// Small in-air views of the folded 3-D target with two ArUco markers.
void RenderSet(const fs::path& dir, int num_images) {
  std::ofstream(dir / "set.yaml")
      << "name: interop\nnum_images: " << num_images << R"(
camera: {model: SIMPLE_RADIAL, width: 800, height: 450, params: [620.0, 400.0, 225.0, -0.02]}
housing: null
)" << testing::kTwoFaceTargetYaml
      << R"(poses: {distance: [0.45, 0.9], tilt_max_deg: 35, roll_max_deg: 60, visibility: markers, border_margin_px: 10, max_view_angle_deg: 60}
render: {spp: 4, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)";
  SynthesizeOptions options;
  options.config_path = (dir / "set.yaml").string();
  options.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(options, progress);
}

std::string Portcal() { return testing::PortcalBinary(); }

TEST(ColmapAutoCalibrationInterop, PortcalFeaturesAreReconstructedByColmapMapper) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  RenderSet(dir.path(), 8);
  const std::string db = (dir / "db.db").string();
  const std::string images = (dir / "set" / "images").string();
  auto result = RunCommand(Portcal() + " feature_extractor --database_path " + db +
                           " --image_path " + images + " --ImageReader.single_camera 1");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunCommand(Portcal() + " exhaustive_matcher --database_path " + db);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  fs::create_directories(dir / "colmap_sparse");
  result =
      RunCommand(colmap + " mapper --database_path " + db + " --image_path " + images +
                 " --output_path " + (dir / "colmap_sparse").string() + " --Mapper.num_threads 2");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const SparseModel model = ReadSparseModel(dir / "colmap_sparse" / "0");
  EXPECT_EQ(model.images.size(), 8u);
  EXPECT_GT(model.points3D.size(), 500u);
}

TEST(ColmapAutoCalibrationInterop, ColmapExtractedDatabaseThroughPortcalStages) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  RenderSet(dir.path(), 8);
  const std::string db = (dir / "db.db").string();
  const std::string images = (dir / "set" / "images").string();
  auto result =
      RunCommand(colmap + " feature_extractor --database_path " + db + " --image_path " + images +
                 " --ImageReader.camera_model SIMPLE_RADIAL --ImageReader.single_camera 1"
                 " --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result =
      RunCommand(Portcal() + " feature_masker --database_path " + db + " --image_path " + images);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  {
    Database database(db, Database::OpenMode::kReadOnly);
    for (const DatabaseImage& image : database.ReadAllImages()) {
      EXPECT_EQ(database.ReadMarkerDetections(image.image_id).size(), 2u) << image.name;
    }
  }
  result = RunCommand(Portcal() + " exhaustive_matcher --database_path " + db);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunCommand(Portcal() + " refractive_mapper --database_path " + db + " --image_path " +
                      images + " --output_path " + (dir / "sparse").string() +
                      " --Markers.side_length 0.06");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // colmap reads portcal's model.
  fs::create_directories(dir / "txt");
  result = RunCommand(colmap + " model_converter --input_path " + (dir / "sparse" / "0").string() +
                      " --output_path " + (dir / "txt").string() + " --output_type TXT");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string text = testing::ReadFileToString(dir / "txt" / "images.txt");
  EXPECT_NE(text.find("Number of images: 8"), std::string::npos) << text.substr(0, 400);
}

TEST(AutoCalibrationStages, RerunSkipsAndFailedStageLeavesTheDatabaseAsItWas) {
  testing::TempDir dir;
  RenderSet(dir.path(), 3);
  const std::string db = (dir / "db.db").string();
  const std::string images = (dir / "set" / "images").string();
  auto result = RunCommand(Portcal() + " feature_extractor --database_path " + db +
                           " --image_path " + images);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunCommand(Portcal() + " feature_extractor --database_path " + db + " --image_path " +
                      images);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("3 skipped"), std::string::npos) << result.output;
  // A masker pointed at the wrong images fails naming the image and writes
  // nothing (not even its stage log row).
  const std::string after_rerun = testing::ReadFileToString(db);
  fs::create_directories(dir / "empty");
  result = RunCommand(Portcal() + " feature_masker --database_path " + db + " --image_path " +
                      (dir / "empty").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("img_"), std::string::npos) << result.output;
  EXPECT_EQ(testing::ReadFileToString(db), after_rerun);
  // Bad option values are named.
  result = RunCommand(Portcal() + " feature_masker --database_path " + db + " --image_path " +
                      images + " --Mask.enlargement_factor 0.5");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--Mask.enlargement_factor"), std::string::npos) << result.output;
  // Markers of another dictionary: no image has one, and masking would
  // remove every feature; an error instead, the database as it was.
  result = RunCommand(Portcal() + " feature_masker --database_path " + db + " --image_path " +
                      images + " --Markers.dictionary DICT_5X5_100");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("no DICT_5X5_100 marker in any of the 3 images"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("--Markers.dictionary"), std::string::npos) << result.output;
  EXPECT_EQ(testing::ReadFileToString(db), after_rerun);
  result = RunCommand(Portcal() + " refractive_mapper --database_path " + db + " --output_path " +
                      (dir / "sparse").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("no verified image pairs"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace portcal
