// database_merger on the two cameras of a rendered chessboard rig, each in
// a database of its own with target corners, SIFT features and matches:
// the first database's rows stay as they were, the second's cameras and
// images follow with new ids and every row about them (features, matches,
// geometries, target observations and detection status) is the second
// database's, under the new ids, in the first's COLMAP layout. A name in
// both, or an existing output, is refused with nothing made.
#include "pipelines/stages/database_merger.h"

#include <gtest/gtest.h>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_matcher.h"
#include "tests/pipelines/stages/live_test_setup.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// One camera's database: its board corners, features and matches, in the
// layout of `version`.
void FillDatabase(const fs::path& images, const fs::path& database, ColmapVersion version) {
  { Database created(database, Database::OpenMode::kCreate, version); }
  testing::ExtractBoard(images, database, false);
  FeatureExtractorOptions extract;
  extract.database_path = database.string();
  extract.image_path = images.string();
  extract.reader.camera_model = "OPENCV";
  extract.reader.single_camera = true;
  extract.sift.max_num_features = 500;
  RunFeatureExtractor(extract, NoProgress());
  FeatureMatcherOptions match;
  match.database_path = database.string();
  RunFeatureMatcher(match, NoProgress());
}

std::string Text(const FeatureMatches& matches) {
  std::string text;
  for (const FeatureMatch& match : matches) {
    text += std::to_string(match.point2D_idx1) + "-" + std::to_string(match.point2D_idx2) + " ";
  }
  return text;
}

// Everything `database` holds about the image `name`, ids left out.
std::string ImageRows(Database* database, const std::string& name) {
  const DatabaseImage image = *database->ReadImageWithName(name);
  const Camera camera = *database->ReadCamera(image.camera_id);
  std::string rows =
      camera.ModelName() + " " + std::to_string(camera.width) + "x" + std::to_string(camera.height);
  for (double p : camera.params) rows += " " + std::to_string(p);
  const FeatureKeypoints keypoints = database->ReadKeypoints(image.image_id);
  rows +=
      "\n" + std::to_string(keypoints.size()) + " keypoints, first at " +
      (keypoints.empty() ? "-"
                         : std::to_string(keypoints[0].x) + "," + std::to_string(keypoints[0].y));
  const FeatureDescriptors descriptors = database->ReadDescriptors(image.image_id);
  rows += "\ndescriptors " + std::to_string(descriptors.rows()) + " sum " +
          std::to_string(descriptors.cast<int>().sum());
  for (const TargetObservation& observation : database->ReadTargetObservations(image.image_id)) {
    rows += "\n" + std::to_string(observation.point_id) + " " + std::to_string(observation.xy.x()) +
            " " + std::to_string(observation.xy.y());
  }
  rows += "\nfound " + std::to_string(database->ReadTargetDetectionStatus(image.image_id)->found);
  return rows;
}

TEST(DatabaseMerger, SecondDatabaseFollowsTheFirstWithNewIds) {
  const testing::TempDir dir;
  testing::RenderSet(dir, testing::LiveStereoTrajectoryYaml(5, 2, false));
  // The rig's first and second camera, 3.8 and 4.1 layouts.
  const fs::path images = dir / "set" / "images";
  std::vector<std::string> folders;
  for (const auto& entry : fs::directory_iterator(images))
    folders.push_back(entry.path().filename().string());
  std::sort(folders.begin(), folders.end());
  ASSERT_EQ(folders.size(), 2u);
  // Each camera's folder under a root of its own: names cam1/..., cam2/...
  for (const std::string& part : {std::string("first"), std::string("second")}) {
    const std::string& folder = folders[part == "first" ? 0 : 1];
    fs::create_directories(dir / part);
    fs::copy(images / folder, dir / part / folder);
  }
  FillDatabase(dir / "first", dir / "first.db", ColmapVersion::k3_8);
  FillDatabase(dir / "second", dir / "second.db", ColmapVersion::k4_1);
  const std::string first_before = testing::ReadFileToString(dir / "first.db");

  DatabaseMergerOptions options;
  options.database_path1 = (dir / "first.db").string();
  options.database_path2 = (dir / "second.db").string();
  options.merged_database_path = (dir / "merged.db").string();
  const DatabaseMergerSummary summary = RunDatabaseMerger(options, NoProgress());
  EXPECT_EQ(testing::ReadFileToString(dir / "first.db"), first_before);

  Database first(dir / "first.db", Database::OpenMode::kReadOnly);
  Database second(dir / "second.db", Database::OpenMode::kReadOnly);
  Database merged(dir / "merged.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(merged.layout().VersionRange(), first.layout().VersionRange());
  EXPECT_EQ(merged.NumCameras(), 2);
  EXPECT_EQ(summary.num_images, second.NumImages());
  EXPECT_EQ(merged.NumImages(), first.NumImages() + second.NumImages());
  EXPECT_EQ(merged.NumVerifiedImagePairs(),
            first.NumVerifiedImagePairs() + second.NumVerifiedImagePairs());
  for (const DatabaseImage& image : first.ReadAllImages()) {
    EXPECT_EQ(merged.ReadImageWithName(image.name)->image_id, image.image_id) << image.name;
    EXPECT_EQ(ImageRows(&merged, image.name), ImageRows(&first, image.name)) << image.name;
  }
  // The second's images after the first's, in their order, on camera 2.
  image_t next = static_cast<image_t>(first.NumImages());
  for (const DatabaseImage& image : second.ReadAllImages()) {
    const DatabaseImage moved = *merged.ReadImageWithName(image.name);
    EXPECT_EQ(moved.image_id, ++next) << image.name;
    EXPECT_EQ(moved.camera_id, 2u) << image.name;
    EXPECT_EQ(ImageRows(&merged, image.name), ImageRows(&second, image.name)) << image.name;
  }
  // A pair of the second database under the new ids.
  const std::vector<DatabaseImage> second_images = second.ReadAllImages();
  const image_t a = second_images[0].image_id, b = second_images[1].image_id;
  const image_t to_a = merged.ReadImageWithName(second_images[0].name)->image_id;
  const image_t to_b = merged.ReadImageWithName(second_images[1].name)->image_id;
  EXPECT_FALSE(second.ReadMatches(a, b).empty());
  EXPECT_EQ(Text(merged.ReadMatches(to_a, to_b)), Text(second.ReadMatches(a, b)));
  EXPECT_EQ(Text(merged.ReadTwoViewGeometry(to_a, to_b)->inlier_matches),
            Text(second.ReadTwoViewGeometry(a, b)->inlier_matches));
}

TEST(DatabaseMerger, ANameInBothOrAnExistingOutputIsRefused) {
  const testing::TempDir dir;
  testing::RenderSet(dir, testing::LiveTrajectoryYaml(5, 2, false));
  FillDatabase(dir / "set" / "images", dir / "first.db", ColmapVersion::k3_8);
  fs::copy_file(dir / "first.db", dir / "copy.db");
  DatabaseMergerOptions options;
  options.database_path1 = (dir / "first.db").string();
  options.database_path2 = (dir / "copy.db").string();
  options.merged_database_path = (dir / "merged.db").string();
  try {
    RunDatabaseMerger(options, NoProgress());
    ADD_FAILURE() << "merged a database with its own copy";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(options.database_path1 + " and " + options.database_path2 +
                                         ": "),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("are in both (img_"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "merged.db"));
  options.merged_database_path = options.database_path2;
  EXPECT_THROW(RunDatabaseMerger(options, NoProgress()), OptionError);
}

}  // namespace
}  // namespace portcal
