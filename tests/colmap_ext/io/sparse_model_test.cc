// Sparse model files: binary and text round trips, the housings sidecar, the
// refractive fork's cameras.txt, and clear errors on bad files.
#include "colmap_ext/io/sparse_model.h"

#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

SparseModel MakeModel() {
  SparseModel model;
  Camera camera = Camera::FromModelName("OPENCV", 1234.5678901234567, 1920, 1080);
  camera.camera_id = 1;
  camera.params[4] = -0.123456789012345;
  model.cameras[1] = camera;
  Camera camera2 = Camera::FromModelName("SIMPLE_RADIAL", 800.25, 640, 480);
  camera2.camera_id = 7;
  model.cameras[7] = camera2;
  for (image_t id : {1u, 2u, 5u}) {
    Image image;
    image.image_id = id;
    image.name = "dir/Bild_" + std::to_string(id) + "_\u00e9'.png";  // non-ASCII and an apostrophe
    image.camera_id = id == 5 ? 7 : 1;
    image.cam_from_world = Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * id, Eigen::Vector3d(1, 2, 3).normalized())),
        Eigen::Vector3d(0.1 * id, -0.2, 1.0 / 3.0));
    for (int k = 0; k < 4; ++k) {
      Point2D point2D;
      point2D.xy = {100.125 + k + id, 200.0 / 3.0 + k};
      image.points2D.push_back(point2D);
    }
    model.images[id] = image;
  }
  Point3D point;
  point.xyz = {0.1, 0.2, 1.0 / 7.0};
  point.color = {255, 0, 17};
  point.error = 0.25;
  point.track = {{1, 0}, {2, 3}, {5, 1}};
  model.points3D[42] = point;
  model.images[1].points2D[0].point3D_id = 42;
  model.images[2].points2D[3].point3D_id = 42;
  model.images[5].points2D[1].point3D_id = 42;
  model.housings[1] =
      Housing::FromName("DOMEPORT", {0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334}, "test");
  return model;
}

void ExpectSameModel(const SparseModel& a, const SparseModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [id, camera] : a.cameras) {
    const Camera& other = b.cameras.at(id);
    EXPECT_EQ(camera.model_id, other.model_id);
    EXPECT_EQ(camera.width, other.width);
    EXPECT_EQ(camera.height, other.height);
    EXPECT_EQ(camera.params, other.params);  // bit-exact, also through text
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [id, image] : a.images) {
    const Image& other = b.images.at(id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.camera_id, other.camera_id);
    EXPECT_EQ(image.cam_from_world.translation, other.cam_from_world.translation);
    EXPECT_LT(image.cam_from_world.rotation.angularDistance(other.cam_from_world.rotation), 1e-15);
    ASSERT_EQ(image.points2D.size(), other.points2D.size());
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      EXPECT_EQ(image.points2D[k].xy, other.points2D[k].xy);
      EXPECT_EQ(image.points2D[k].point3D_id, other.points2D[k].point3D_id);
    }
  }
  ASSERT_EQ(a.points3D.size(), b.points3D.size());
  for (const auto& [id, point] : a.points3D) {
    const Point3D& other = b.points3D.at(id);
    EXPECT_EQ(point.xyz, other.xyz);
    EXPECT_EQ(point.color, other.color);
    EXPECT_EQ(point.error, other.error);
    ASSERT_EQ(point.track.size(), other.track.size());
  }
  ASSERT_EQ(a.housings.size(), b.housings.size());
  for (const auto& [id, housing] : a.housings) {
    EXPECT_EQ(housing.model_id, b.housings.at(id).model_id);
    EXPECT_EQ(housing.params, b.housings.at(id).params);
  }
}

TEST(SparseModel, BinaryAndTextRoundTripsAreExact) {
  testing::TempDir dir;
  const SparseModel model = MakeModel();
  WriteSparseModel(model, dir / "bin", ModelFormat::kBinary);
  WriteSparseModel(model, dir / "txt", ModelFormat::kText);
  ExpectSameModel(model, ReadSparseModel(dir / "bin"));
  ExpectSameModel(model, ReadSparseModel(dir / "txt"));
  // bin -> txt -> bin reproduces the binary files byte for byte.
  WriteSparseModel(ReadSparseModel(dir / "txt"), dir / "bin2", ModelFormat::kBinary);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    EXPECT_EQ(testing::ReadFileToString(dir / "bin" / name),
              testing::ReadFileToString(dir / "bin2" / name))
        << name;
  }
  EXPECT_TRUE(fs::exists(dir / "bin" / "housings.txt"));
}

// colmap_ext/util/image_name.h: a space is kept in BIN and refused in
// images.txt (COLMAP reads a name there up to the first space); a control
// character is refused on both sides, naming the image.
TEST(SparseModel, ImageNamesFollowOnePolicy) {
  testing::TempDir dir;
  SparseModel model = MakeModel();
  model.images.at(2).name = "dir/img 2.png";
  WriteSparseModel(model, dir / "bin", ModelFormat::kBinary);
  ExpectSameModel(model, ReadSparseModel(dir / "bin"));
  try {
    WriteSparseModel(model, dir / "txt", ModelFormat::kText);
    ADD_FAILURE() << "a name with a space went to images.txt";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dir/img 2.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("BIN"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "txt" / "images.txt"));
  model.images.at(2).name = "dir/img\n2.png";
  EXPECT_THROW(WriteSparseModel(model, dir / "bin_newline", ModelFormat::kBinary), InputError);
  // Read: a .bin whose name holds a tab.
  std::string images = testing::ReadFileToString(dir / "bin" / "images.bin");
  const size_t at = images.find("dir/img 2.png");
  ASSERT_NE(at, std::string::npos);
  images[at + 7] = '\t';
  std::ofstream(dir / "bin" / "images.bin", std::ios::binary) << images;
  try {
    ReadSparseModel(dir / "bin");
    ADD_FAILURE() << "a name with a tab was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dir/img\\x092.png"), std::string::npos) << e.what();
  }
}

TEST(SparseModel, ImportsTheRefractiveForksCamerasTxt) {
  testing::TempDir dir;
  fs::create_directories(dir / "fork");
  {
    std::ofstream out(dir / "fork" / "cameras.txt");
    out << "# Camera list\n"
        << "1 RADIAL 1920 1080 1297.3655 960 540 0 0 DOMEPORT 0.01 0.006 0.002 "
           "0.05 0.006 1.0 1.473 1.334\n"
        << "2 PINHOLE 640 480 500 500 320 240\n"
        << "3 SIMPLE_PINHOLE 640 480 500 320 240 FLATPORT 0 0 1 0.02 0.014 1 1.473 1.334\n";
    std::ofstream(dir / "fork" / "images.txt") << "# empty\n";
    std::ofstream(dir / "fork" / "points3D.txt") << "# empty\n";
  }
  const SparseModel model = ReadSparseModel(dir / "fork");
  ASSERT_EQ(model.cameras.size(), 3u);
  ASSERT_EQ(model.housings.size(), 2u);
  EXPECT_EQ(model.housings.at(1).ModelName(), "DOMEPORT");
  EXPECT_EQ(model.housings.at(3).ModelName(), "FLATPORT");
  EXPECT_EQ(model.cameras.at(1).params.size(), 5u);
  // Written out, stock COLMAP files plus housings.txt.
  WriteSparseModel(model, dir / "out", ModelFormat::kText);
  const std::string cameras = testing::ReadFileToString(dir / "out" / "cameras.txt");
  EXPECT_EQ(cameras.find("DOMEPORT"), std::string::npos);
  const SparseModel again = ReadSparseModel(dir / "out");
  ExpectSameModel(model, again);
}

TEST(SparseModel, BadFilesGiveErrorsNamingTheFile) {
  testing::TempDir dir;
  WriteSparseModel(MakeModel(), dir.path(), ModelFormat::kBinary);
  // Truncate images.bin.
  const std::string images = testing::ReadFileToString(dir / "images.bin");
  std::ofstream(dir / "images.bin", std::ios::binary | std::ios::trunc)
      << images.substr(0, images.size() / 2);
  try {
    ReadSparseModel(dir.path());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images.bin"), std::string::npos) << e.what();
  }
  testing::TempDir text_dir;
  WriteSparseModel(MakeModel(), text_dir.path(), ModelFormat::kText);
  std::ofstream(text_dir / "cameras.txt") << "1 OPENCV 1920 1080 1000 1000 960 540\n";
  try {
    ReadSparseModel(text_dir.path());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.txt:1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("8 parameters"), std::string::npos) << e.what();
  }
  std::ofstream(text_dir / "cameras.txt") << "1 PINHOLE 1920 1080 1000 nan 960 540\n";
  EXPECT_THROW(ReadSparseModel(text_dir.path()), InputError);
  EXPECT_THROW(ReadSparseModel(dir / "missing"), InputError);
}

TEST(SparseModel, DanglingReferencesAreRejected) {
  SparseModel model = MakeModel();
  model.images[2].camera_id = 99;
  EXPECT_THROW(model.Validate("m"), InputError);
  model = MakeModel();
  model.points3D[42].track.push_back({5, 17});
  EXPECT_THROW(model.Validate("m"), InputError);
  model = MakeModel();
  model.housings[99] = model.housings[1];
  EXPECT_THROW(model.Validate("m"), InputError);
}

TEST(SparseModel, FailedWriteLeavesNoPartialFile) {
  testing::TempDir dir;
  SparseModel model = MakeModel();
  model.images[2].camera_id = 99;  // invalid: rejected before anything is written
  EXPECT_THROW(WriteSparseModel(model, dir / "out", ModelFormat::kBinary), InputError);
  EXPECT_FALSE(fs::exists(dir / "out" / "cameras.bin"));
  EXPECT_THROW(
      WriteFileAtomically(dir / "x.txt", false, [](std::ostream&) { throw InputError("boom"); }),
      InputError);
  EXPECT_FALSE(fs::exists(dir / "x.txt"));
  EXPECT_FALSE(fs::exists(dir / "x.txt.tmp"));
}

}  // namespace
}  // namespace portcal
