// refractive_mapper's --image_list_path (COLMAP's option): only the listed
// images, and the pairs between them, are mapped; a list naming an image
// the database does not hold, an empty list and a missing file are errors
// naming the file (and line), with no output folder left. The list
// calibration_subset_selector writes maps as one model. A pair excluded as
// the initial pair is not started from.
#include "pipelines/stages/refractive_mapper.h"

#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "pipelines/stages/calibration_subset_selector.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_matcher.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Seven views of the two-face ArUco target, extracted and matched.
fs::path MatchedDatabase(const testing::TempDir& dir) {
  testing::RenderSet(
      dir, std::string("name: mapper_list\nnum_images: 7\nseed: 5\n") +
               "camera: {model: SIMPLE_RADIAL, width: 640, height: 360, params: [500.0, 320.0, "
               "180.0, -0.02]}\nhousing: null\n" +
               testing::kTwoFaceTargetYaml +
               "poses: {distance: [0.45, 0.9], tilt_max_deg: 35, roll_max_deg: 60, visibility: "
               "markers, border_margin_px: 10, max_view_angle_deg: 60}\n"
               "render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}\n");
  FeatureExtractorOptions extract;
  extract.database_path = (dir / "db.db").string();
  extract.image_path = (dir / "set" / "images").string();
  extract.reader.single_camera = true;
  RunFeatureExtractor(extract, NoProgress());
  FeatureMatcherOptions match;
  match.database_path = extract.database_path;
  RunFeatureMatcher(match, NoProgress());
  return dir / "db.db";
}

RefractiveMapperOptions MapperOptions(const testing::TempDir& dir, const fs::path& database) {
  RefractiveMapperOptions options;
  options.database_path = database.string();
  options.output_path = (dir / "sparse").string();
  options.image_list_path = (dir / "list.txt").string();
  options.mapper.num_threads = 1;
  return options;
}

TEST(RefractiveMapper, ImageListMapsOnlyTheListedImages) {
  const testing::TempDir dir;
  const fs::path database = MatchedDatabase(dir);
  const std::set<std::string> listed = {"img_002.png", "img_003.png", "img_004.png", "img_005.png"};
  {
    std::ofstream list(dir / "list.txt");
    list << "\n";  // blank lines and surrounding blanks are ignored
    for (const std::string& name : listed) list << "  " << name << " \n";
  }
  const RefractiveMapperSummary summary =
      RunRefractiveMapper(MapperOptions(dir, database), NoProgress());
  EXPECT_EQ(summary.num_images, 4);
  ASSERT_EQ(summary.num_models, 1);
  const SparseModel model = ReadSparseModel(summary.model_paths[0]);
  EXPECT_EQ(model.images.size(), 4u);
  for (const auto& [id, image] : model.images)
    EXPECT_EQ(listed.count(image.name), 1u) << image.name;
}

// The auto-calibrator's next start excludes the pair the previous start's
// model grew from (IncrementalMapperOptions::init_excluded_pairs).
TEST(RefractiveMapper, AnExcludedPairIsNotStartedFrom) {
  const testing::TempDir dir;
  const fs::path database = MatchedDatabase(dir);
  RefractiveMapperOptions options = MapperOptions(dir, database);
  options.image_list_path.clear();
  const RefractiveMapperSummary first = RunRefractiveMapper(options, NoProgress());
  ASSERT_EQ(first.initial_pairs.size(), static_cast<size_t>(first.num_models));
  ASSERT_GE(first.num_models, 1);
  options.output_path = (dir / "sparse_again").string();
  options.mapper.init_excluded_pairs = {first.initial_pairs[0]};
  const RefractiveMapperSummary again = RunRefractiveMapper(options, NoProgress());
  ASSERT_GE(again.num_models, 1);
  for (image_pair_t pair : again.initial_pairs) EXPECT_NE(pair, first.initial_pairs[0]);
  EXPECT_EQ(again.num_registered, 7);
}

TEST(RefractiveMapper, ABadImageListIsNamed) {
  const testing::TempDir dir;
  const fs::path database = MatchedDatabase(dir);
  const RefractiveMapperOptions options = MapperOptions(dir, database);
  const auto expect_error = [&](const std::string& list, const std::string& words) {
    if (list == "missing") {
      fs::remove(dir / "list.txt");
    } else {
      std::ofstream(dir / "list.txt") << list;
    }
    try {
      RunRefractiveMapper(options, NoProgress());
      ADD_FAILURE() << "accepted the list '" << list << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "sparse"));
  };
  expect_error("img_001.png\nnope.png\n",
               options.image_list_path + ":2: image 'nope.png' is not in");
  expect_error("\n \n", options.image_list_path + ": no image names");
  expect_error("missing", options.image_list_path + ": cannot read the image list");
}

TEST(RefractiveMapper, TheSubsetSelectorsListMapsAsOneModel) {
  const testing::TempDir dir;
  const fs::path database = MatchedDatabase(dir);
  CalibrationSubsetSelectorOptions select;
  select.database_path = database.string();
  select.output_path = (dir / "list.txt").string();
  select.subset.num_images = 4;
  const CalibrationSubsetSelectorSummary selected =
      RunCalibrationSubsetSelector(select, NoProgress());
  EXPECT_EQ(selected.num_images, 7);
  EXPECT_EQ(selected.num_breaks, 0);
  EXPECT_GE(selected.num_selected, 4);
  EXPECT_LT(selected.num_selected, 7);
  const RefractiveMapperSummary mapped =
      RunRefractiveMapper(MapperOptions(dir, database), NoProgress());
  EXPECT_EQ(mapped.num_models, 1);
  EXPECT_EQ(mapped.num_registered, selected.num_selected);
}

}  // namespace
}  // namespace portcal
