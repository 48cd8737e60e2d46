// feature_extractor reruns: images that have features keep them, but their
// cameras still meet the reader options (as target_extractor's do): other
// options are an error naming the difference, the database untouched, and
// --ImageReader.overwrite imports the cameras again with the features kept.
#include "pipelines/stages/feature_extractor.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

void WriteTexturedImages(const fs::path& dir) {
  fs::create_directories(dir);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> grey(0, 255);
  for (const char* name : {"a.png", "b.png", "c.png"}) {
    cv::Mat small(12, 16, CV_8UC1);
    for (int y = 0; y < small.rows; ++y) {
      for (int x = 0; x < small.cols; ++x)
        small.at<uint8_t>(y, x) = static_cast<uint8_t>(grey(rng));
    }
    cv::Mat image;
    cv::resize(small, image, cv::Size(160, 120), 0, 0, cv::INTER_CUBIC);
    cv::imwrite((dir / name).string(), image);
  }
}

TEST(FeatureExtractor, ARerunWithOtherReaderOptionsSaysSoOrImportsTheCamerasAgain) {
  testing::TempDir dir;
  WriteTexturedImages(dir / "images");
  NullProgress progress;
  FeatureExtractorOptions first;
  first.database_path = (dir / "db.db").string();
  first.image_path = (dir / "images").string();
  first.reader.camera_model = "SIMPLE_RADIAL";
  first.reader.single_camera = false;
  ASSERT_EQ(RunFeatureExtractor(first, progress).num_extracted, 3);
  int64_t num_keypoints = 0;
  {
    Database db(dir / "db.db", Database::OpenMode::kReadOnly);
    ASSERT_EQ(db.NumCameras(), 3);
    for (const DatabaseImage& image : db.ReadAllImages())
      num_keypoints += db.ReadKeypoints(image.image_id).size();
  }
  ASSERT_GT(num_keypoints, 0);
  const std::string before = testing::ReadFileToString(dir / "db.db");

  // Every image has features, so none is extracted: the options are checked
  // all the same.
  FeatureExtractorOptions second = first;
  second.reader.camera_model = "OPENCV";
  second.reader.single_camera = true;
  try {
    RunFeatureExtractor(second, progress);
    FAIL() << "a rerun with other reader options went through";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("a.png"), std::string::npos) << what;
    EXPECT_NE(what.find("--ImageReader.overwrite 1"), std::string::npos) << what;
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);

  second.reader.overwrite = true;
  const FeatureExtractorSummary summary = RunFeatureExtractor(second, progress);
  EXPECT_EQ(summary.num_skipped, 3);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  ASSERT_EQ(db.NumCameras(), 1);
  EXPECT_EQ(db.ReadAllCameras().front().ModelName(), "OPENCV");
  int64_t kept = 0;
  for (const DatabaseImage& image : db.ReadAllImages()) {
    EXPECT_EQ(image.camera_id, db.ReadAllCameras().front().camera_id) << image.name;
    kept += db.ReadKeypoints(image.image_id).size();
  }
  EXPECT_EQ(kept, num_keypoints);
}

}  // namespace
}  // namespace portcal
