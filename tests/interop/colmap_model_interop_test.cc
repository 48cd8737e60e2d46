// Sparse models and camera models against the real `colmap` 3.8 binary:
// model_converter round trips both ways, and point_filtering as an oracle for
// COLMAP's projection of every camera model.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::ReadFileToString;
using testing::RunCommand;

// Two images looking at a cloud of points, with exact observations.
SparseModel TwoViewModel(const Camera& camera, int num_points, uint32_t seed) {
  SparseModel model;
  model.cameras[camera.camera_id] = camera;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (image_t id : {1u, 2u}) {
    Image image;
    image.image_id = id;
    image.name = "image" + std::to_string(id) + ".png";
    image.camera_id = camera.camera_id;
    image.cam_from_world = Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(id == 1 ? 0.0 : 0.15, Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(id == 1 ? 0.0 : -0.5, 0.02 * id, 0.0));
    model.images[id] = image;
  }
  point3D_t next_id = 1;
  while (static_cast<int>(model.points3D.size()) < num_points) {
    const Eigen::Vector3d xyz(1.2 * uniform(rng), 0.9 * uniform(rng), 3.0 + uniform(rng));
    std::vector<Eigen::Vector2d> pixels;
    for (const auto& [id, image] : model.images) {
      const std::optional<Eigen::Vector2d> pixel = camera.ImgFromCam(image.cam_from_world * xyz);
      if (pixel && pixel->x() > 0 && pixel->y() > 0 && pixel->x() < camera.width &&
          pixel->y() < camera.height) {
        pixels.push_back(*pixel);
      }
    }
    if (pixels.size() != 2) continue;
    Point3D point;
    point.xyz = xyz;
    point.error = 0.0;
    for (image_t id : {1u, 2u}) {
      Image& image = model.images[id];
      Point2D point2D;
      point2D.xy = pixels[id - 1];
      point2D.point3D_id = next_id;
      point.track.push_back({id, static_cast<point2D_t>(image.points2D.size())});
      image.points2D.push_back(point2D);
    }
    model.points3D[next_id++] = point;
  }
  return model;
}

Camera TestCamera(const std::string& model_name) {
  Camera camera = Camera::FromModelName(model_name, 700.0, 1000, 800);
  camera.camera_id = 3;
  const int offset = static_cast<int>(CameraModelFocalLengthIdxs(camera.model_id).size());
  camera.params[0] = 712.5;
  if (offset == 2) camera.params[1] = 690.25;
  camera.params[offset] = 503.5;
  camera.params[offset + 1] = 398.75;
  const std::vector<int> extra = CameraModelExtraParamsIdxs(camera.model_id);
  const double values[] = {-0.08, 0.012, 0.0011, -0.0009, 0.004, 0.002, 0.001, 0.0005};
  for (size_t i = 0; i < extra.size(); ++i) camera.params[extra[i]] = values[i];
  if (model_name == "FOV") camera.params[4] = 0.9;
  return camera;
}

// COLMAP keeps a 3D point only if both observations reproject within
// max_reproj_error under COLMAP's own camera model. Points whose second
// observation was moved by 1e-4 px must go, the exact ones must stay: the two
// implementations then agree to better than 1e-6 px.
TEST(ColmapModelInterop, EveryCameraModelProjectsLikeColmap) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  for (int model_id = 0; model_id < kNumCameraModels; ++model_id) {
    const std::string name = CameraModelIdToName(model_id);
    testing::TempDir dir;
    SparseModel model = TwoViewModel(TestCamera(name), 40, 7 + model_id);
    std::set<point3D_t> moved;
    for (Point2D& point2D : model.images[2].points2D) {
      if (point2D.point3D_id % 2 == 0) {
        point2D.xy.x() += 1e-4;
        moved.insert(point2D.point3D_id);
      }
    }
    WriteSparseModel(model, dir / "in", ModelFormat::kBinary);
    fs::create_directories(dir / "out");
    const auto result = RunCommand(
        colmap + " point_filtering --input_path " + (dir / "in").string() + " --output_path " +
        (dir / "out").string() + " --min_track_len 2 --min_tri_angle 0 --max_reproj_error 1e-6");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    const SparseModel filtered = ReadSparseModel(dir / "out");
    EXPECT_EQ(filtered.points3D.size(), model.points3D.size() - moved.size()) << name;
    for (const auto& [id, point] : filtered.points3D) {
      EXPECT_EQ(moved.count(id), 0u) << name << " kept moved point " << id;
    }
  }
}

// Header lines, then the data records (groups of `lines_per_record` lines)
// sorted.
std::vector<std::string> TextRecords(const std::string& text, int lines_per_record) {
  std::vector<std::string> header, records;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') {
      header.push_back(line);
      continue;
    }
    std::string record = line;
    for (int k = 1; k < lines_per_record && std::getline(in, line); ++k) {
      record += "\n" + line;
    }
    records.push_back(record);
  }
  std::sort(records.begin(), records.end());
  header.insert(header.end(), records.begin(), records.end());
  return header;
}

SparseModel RichModel() {
  Camera camera = TestCamera("OPENCV");
  SparseModel model = TwoViewModel(camera, 25, 3);
  Camera second = TestCamera("SIMPLE_RADIAL");
  second.camera_id = 9;
  model.cameras[9] = second;
  model.images[2].camera_id = 9;
  // An unobserved 2D point (point3D_id -1) and a name with a subdirectory.
  model.images[1].points2D.push_back(Point2D{Eigen::Vector2d(10.125, 20.5), kInvalidPoint3DId});
  model.images[1].name = "sub/dir/image1.png";
  return model;
}

TEST(ColmapModelInterop, ColmapConvertsPortcalsBinaryToTheSameText) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  const SparseModel model = RichModel();
  WriteSparseModel(model, dir / "bin", ModelFormat::kBinary);
  WriteSparseModel(model, dir / "portcal_txt", ModelFormat::kText);
  fs::create_directories(dir / "colmap_txt");
  const auto result =
      RunCommand(colmap + " model_converter --input_path " + (dir / "bin").string() +
                 " --output_path " + (dir / "colmap_txt").string() + " --output_type TXT");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Same values (bit-exact: 17 digits on both sides)...
  const SparseModel colmap_model = ReadSparseModel(dir / "colmap_txt");
  ASSERT_EQ(colmap_model.points3D.size(), model.points3D.size());
  for (const auto& [id, camera] : model.cameras) {
    EXPECT_EQ(colmap_model.cameras.at(id).params, camera.params);
  }
  for (const auto& [id, image] : model.images) {
    const Image& other = colmap_model.images.at(id);
    EXPECT_EQ(other.name, image.name);
    EXPECT_EQ(other.cam_from_world.translation, image.cam_from_world.translation);
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      EXPECT_EQ(other.points2D[k].xy, image.points2D[k].xy);
      EXPECT_EQ(other.points2D[k].point3D_id, image.points2D[k].point3D_id);
    }
  }
  // ... and the same bytes: identical headers and identical record lines.
  // COLMAP writes records in its hash maps' order, portcal by increasing id,
  // so records are compared as sorted lists.
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    const int lines_per_record = std::string(name) == "images.txt" ? 2 : 1;
    EXPECT_EQ(TextRecords(ReadFileToString(dir / "colmap_txt" / name), lines_per_record),
              TextRecords(ReadFileToString(dir / "portcal_txt" / name), lines_per_record))
        << name;
  }
}

TEST(ColmapModelInterop, ColmapConvertsPortcalsTextToTheSameBinary) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  const SparseModel model = RichModel();
  WriteSparseModel(model, dir / "txt", ModelFormat::kText);
  WriteSparseModel(model, dir / "portcal_bin", ModelFormat::kBinary);
  fs::create_directories(dir / "colmap_bin");
  const auto result =
      RunCommand(colmap + " model_converter --input_path " + (dir / "txt").string() +
                 " --output_path " + (dir / "colmap_bin").string() + " --output_type BIN");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Same sizes; and read back and rewritten in portcal's (sorted) record
  // order, COLMAP's files are byte-identical to portcal's.
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    EXPECT_EQ(fs::file_size(dir / "colmap_bin" / name), fs::file_size(dir / "portcal_bin" / name))
        << name;
  }
  WriteSparseModel(ReadSparseModel(dir / "colmap_bin"), dir / "rewritten", ModelFormat::kBinary);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    EXPECT_TRUE(ReadFileToString(dir / "rewritten" / name) ==
                ReadFileToString(dir / "portcal_bin" / name))
        << name;
  }
}

TEST(ColmapModelInterop, HousingsSidecarDoesNotDisturbColmap) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  SparseModel model = RichModel();
  model.housings[3] =
      Housing::FromName("DOMEPORT", {0.001, 0.0, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334}, "test");
  WriteSparseModel(model, dir / "bin", ModelFormat::kBinary);
  fs::create_directories(dir / "out");
  const auto result =
      RunCommand(colmap + " model_converter --input_path " + (dir / "bin").string() +
                 " --output_path " + (dir / "out").string() + " --output_type TXT");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(ReadSparseModel(dir / "out").cameras.size(), 2u);
}

}  // namespace
}  // namespace portcal
