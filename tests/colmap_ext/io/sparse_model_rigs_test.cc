// Rig and frame files of COLMAP 3.12+ models: a text model in COLMAP 4.1's
// format reads and writes back byte for byte, a binary one too; a model
// without them stays without; and the rigs COLMAP 3.12 on makes of a
// legacy model are one per camera, a frame per image.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Two cameras on one rig (camera 2 half a metre right of camera 1, turned
// slightly), an IMU without a calibrated pose, and two frames.
const char* const kRigsText =
    "# Rig calib list with one line of data per calib:\n"
    "#   RIG_ID, NUM_SENSORS, REF_SENSOR_TYPE, REF_SENSOR_ID, SENSORS[] as (SENSOR_TYPE, "
    "SENSOR_ID, HAS_POSE, "
    "[QW, QX, QY, QZ, TX, TY, TZ])\n"
    "# Number of rigs: 1\n"
    "1 3 CAMERA 1 CAMERA 2 1 0.99995000374993748 0 0.0099998333341666645 0 -0.5 0 0 IMU 7 0\n";
const char* const kFramesText =
    "# Frame list with one line of data per frame:\n"
    "#   FRAME_ID, RIG_ID, RIG_FROM_WORLD[QW, QX, QY, QZ, TX, TY, TZ], NUM_DATA_IDS, DATA_IDS[] as "
    "(SENSOR_TYPE, SENSOR_ID, DATA_ID)\n"
    "# Number of frames: 2\n"
    "1 1 1 0 0 0 0 0 2 2 CAMERA 1 1 CAMERA 2 2\n"
    "2 1 1 0 0 0 -0.10000000000000001 0 2 2 CAMERA 1 3 CAMERA 2 4\n";

SparseModel TwoCameraModel() {
  SparseModel model;
  for (camera_t id : {1u, 2u}) {
    model.cameras[id] = Camera::FromModelName("PINHOLE", 500, 640, 480);
    model.cameras[id].camera_id = id;
  }
  for (image_t id = 1; id <= 4; ++id) {
    Image& image = model.images[id];
    image.image_id = id;
    image.name = "im" + std::to_string(id) + ".png";
    image.camera_id = id % 2 == 1 ? 1 : 2;
  }
  return model;
}

TEST(SparseModelRigs, ColmapTextReadsAndWritesBackByteForByte) {
  testing::TempDir dir;
  WriteSparseModel(TwoCameraModel(), dir / "model", ModelFormat::kText);
  std::ofstream(dir / "model" / "rigs.txt") << kRigsText;
  std::ofstream(dir / "model" / "frames.txt") << kFramesText;
  const SparseModel model = ReadSparseModel(dir / "model");
  ASSERT_EQ(model.rigs.size(), 1u);
  const ModelRig& rig = model.rigs.at(1);
  ASSERT_TRUE(rig.ref_sensor);
  EXPECT_EQ(rig.ref_sensor->id, 1u);
  ASSERT_EQ(rig.sensors.size(), 2u);
  ASSERT_TRUE(rig.sensors[0].second);
  EXPECT_DOUBLE_EQ(rig.sensors[0].second->translation.x(), -0.5);
  EXPECT_EQ(rig.sensors[1].first.type, 1);  // IMU
  EXPECT_FALSE(rig.sensors[1].second);
  ASSERT_EQ(model.frames.size(), 2u);
  EXPECT_EQ(model.frames.at(2).data[1].second, 4u);
  EXPECT_DOUBLE_EQ(model.frames.at(2).rig_from_world.translation.x(), -0.1);
  WriteSparseModel(model, dir / "again", ModelFormat::kText);
  EXPECT_EQ(testing::ReadFileToString(dir / "again" / "rigs.txt"), kRigsText);
  EXPECT_EQ(testing::ReadFileToString(dir / "again" / "frames.txt"), kFramesText);
  // Binary: written, read back, written again, the same bytes.
  WriteSparseModel(model, dir / "bin", ModelFormat::kBinary);
  const SparseModel binary = ReadSparseModel(dir / "bin");
  WriteSparseModel(binary, dir / "bin2", ModelFormat::kBinary);
  for (const char* file : {"rigs.bin", "frames.bin"}) {
    EXPECT_EQ(testing::ReadFileToString(dir / "bin" / file),
              testing::ReadFileToString(dir / "bin2" / file))
        << file;
  }
  WriteSparseModel(binary, dir / "text2", ModelFormat::kText);
  EXPECT_EQ(testing::ReadFileToString(dir / "text2" / "frames.txt"), kFramesText);
}

TEST(SparseModelRigs, LegacyModelsStayLegacyAndGetOneRigPerCamera) {
  testing::TempDir dir;
  SparseModel model = TwoCameraModel();
  WriteSparseModel(model, dir / "legacy", ModelFormat::kBinary);
  EXPECT_FALSE(fs::exists(dir / "legacy" / "rigs.bin"));
  EXPECT_TRUE(ReadSparseModel(dir / "legacy").rigs.empty());
  model.images.at(3).cam_from_world.translation = Eigen::Vector3d(0, 0, 1);
  AddOneRigPerCamera(&model);
  ASSERT_EQ(model.rigs.size(), 2u);
  EXPECT_EQ(model.rigs.at(2).ref_sensor->id, 2u);
  EXPECT_TRUE(model.rigs.at(2).sensors.empty());
  ASSERT_EQ(model.frames.size(), 4u);
  EXPECT_EQ(model.frames.at(3).rig_id, 1u);
  EXPECT_EQ(model.frames.at(3).data.size(), 1u);
  EXPECT_EQ(model.frames.at(3).data[0].second, 3u);
  EXPECT_EQ(model.frames.at(3).rig_from_world.translation.z(), 1.0);
}

TEST(SparseModelRigs, DamagedFilesNameTheFileAndLine) {
  testing::TempDir dir;
  WriteSparseModel(TwoCameraModel(), dir / "model", ModelFormat::kText);
  std::ofstream(dir / "model" / "rigs.txt") << "1 2 CAMERA 1 ROBOT 2 0\n";
  std::ofstream(dir / "model" / "frames.txt") << kFramesText;
  try {
    ReadSparseModel(dir / "model");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rigs.txt:1"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "model" / "rigs.txt") << kRigsText;
  std::ofstream(dir / "model" / "frames.txt") << "1 9 1 0 0 0 0 0 0 1 CAMERA 1 1\n";
  EXPECT_THROW(ReadSparseModel(dir / "model"), InputError);  // frame of an unknown rig
}

}  // namespace
}  // namespace portcal
