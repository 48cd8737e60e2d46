// feature_masker reruns: the same mask again changes nothing; another mask
// starts from the features as extracted (kept aside at the first masking);
// where they were not kept, another mask is refused with the reason and the
// way out, the database untouched.
#include "pipelines/stages/feature_masker.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Renders `num_images` views of the two-face target into dir/set and
// extracts their features into dir/db.db; returns the extraction's options.
FeatureExtractorOptions RenderAndExtract(const fs::path& dir, int num_images, int seed) {
  std::ofstream(dir / "set.yaml")
      << "name: mask\nnum_images: " << num_images << "\nseed: " << seed << "\n"
      << "camera: {model: RADIAL, width: 480, height: 270, params: [330.0, 240.0, 135.0, 0.0, "
         "0.0]}\n"
      << "housing: null\n"
      << testing::kTwoFaceTargetYaml
      << "poses: {distance: [0.4, 0.7], tilt_max_deg: 30, roll_max_deg: 30, visibility: markers}\n"
      << "render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}\n";
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  FeatureExtractorOptions extract;
  extract.database_path = (dir / "db.db").string();
  extract.image_path = (dir / "set/images").string();
  extract.reader.single_camera = true;
  RunFeatureExtractor(extract, progress);
  return extract;
}

TEST(FeatureMasker, AnotherMaskStartsFromTheFeaturesAsExtracted) {
  testing::TempDir dir;
  FeatureExtractorOptions extract = RenderAndExtract(dir.path(), 3, 3);
  NullProgress progress;
  FeatureMaskerOptions mask;
  mask.database_path = extract.database_path;
  mask.image_path = extract.image_path;
  mask.enlargement_factor = 3.0;
  const FeatureMaskerSummary first = RunFeatureMasker(mask, progress);
  ASSERT_LT(first.num_features_kept, first.num_features_before);
  const FeatureMaskerSummary again = RunFeatureMasker(mask, progress);
  EXPECT_EQ(again.num_features_kept, first.num_features_kept);
  EXPECT_EQ(again.num_features_before,
            first.num_features_before);  // from the features as extracted
  const auto matched_keypoints = [&] {
    Database db(dir / "db.db", Database::OpenMode::kReadOnly);
    std::vector<FeatureKeypoints> keypoints;
    for (const DatabaseImage& image : db.ReadAllImages())
      keypoints.push_back(db.ReadKeypoints(image.image_id));
    return keypoints;
  };
  const std::vector<FeatureKeypoints> first_keypoints = matched_keypoints();

  // A wider mask starts from the features as extracted, not from what the
  // first mask left; a narrower one after it keeps a subset.
  mask.enlargement_factor = 5.0;
  const FeatureMaskerSummary wider = RunFeatureMasker(mask, progress);
  EXPECT_EQ(wider.num_features_before, first.num_features_before);
  EXPECT_GT(wider.num_features_kept, first.num_features_kept);
  mask.enlargement_factor = 3.0;
  const FeatureMaskerSummary back = RunFeatureMasker(mask, progress);
  EXPECT_EQ(back.num_features_kept, first.num_features_kept);
  const std::vector<FeatureKeypoints> back_keypoints = matched_keypoints();
  ASSERT_EQ(back_keypoints.size(), first_keypoints.size());
  for (size_t i = 0; i < back_keypoints.size(); ++i) {
    ASSERT_EQ(back_keypoints[i].size(), first_keypoints[i].size()) << i;
    for (size_t k = 0; k < back_keypoints[i].size(); ++k) {
      EXPECT_EQ(back_keypoints[i][k].x, first_keypoints[i][k].x);
      EXPECT_EQ(back_keypoints[i][k].y, first_keypoints[i][k].y);
    }
  }

  // Extracted again, the kept features are gone with the old ones: the
  // mask starts from the new extraction.
  extract.overwrite = true;
  RunFeatureExtractor(extract, progress);
  {
    Database db(dir / "db.db", Database::OpenMode::kReadOnly);
    EXPECT_EQ(db.NumImagesWithUnmaskedFeatures(), 0);
  }
  const FeatureMaskerSummary extracted_again = RunFeatureMasker(mask, progress);
  EXPECT_EQ(extracted_again.num_features_before, first.num_features_before);
  EXPECT_EQ(extracted_again.num_features_kept, first.num_features_kept);
}

// --Mask.keep_all_features after a mask: every image gets its features as
// extracted back, the one without markers (all its features masked away)
// too, and the markers stay stored.
TEST(FeatureMasker, KeepingAllFeaturesAfterAMaskBringsEveryImagesBack) {
  testing::TempDir dir;
  FeatureExtractorOptions extract = RenderAndExtract(dir.path(), 2, 5);
  ASSERT_TRUE(cv::imwrite((dir / "set/images/no_markers.png").string(),
                          testing::ClutteredScene(480, 270, 9)));
  NullProgress progress;
  RunFeatureExtractor(extract, progress);  // the new image only
  const auto counts = [&] {
    Database db(dir / "db.db", Database::OpenMode::kReadOnly);
    std::map<std::string, size_t> keypoints;
    for (const DatabaseImage& image : db.ReadAllImages())
      keypoints[image.name] = db.ReadKeypoints(image.image_id).size();
    return keypoints;
  };
  const std::map<std::string, size_t> extracted = counts();
  ASSERT_EQ(extracted.size(), 3u);
  ASSERT_GT(extracted.at("no_markers.png"), 0u);
  FeatureMaskerOptions mask;
  mask.database_path = extract.database_path;
  mask.image_path = extract.image_path;
  const FeatureMaskerSummary masked = RunFeatureMasker(mask, progress);
  EXPECT_EQ(masked.num_without_markers, 1);
  EXPECT_EQ(counts().at("no_markers.png"), 0u);
  mask.keep_all_features = true;
  const FeatureMaskerSummary kept = RunFeatureMasker(mask, progress);
  EXPECT_EQ(kept.num_features_kept, kept.num_features_before);
  EXPECT_EQ(kept.num_markers, masked.num_markers);
  EXPECT_EQ(counts(), extracted);
}

// A database masked by a portcal that did not keep the features as
// extracted (no portcal_unmasked_features rows): another mask is refused
// with the reason and the way out, the database untouched.
TEST(FeatureMasker, AnotherMaskWithoutTheExtractedFeaturesIsRefused) {
  testing::TempDir dir;
  const FeatureExtractorOptions extract = RenderAndExtract(dir.path(), 2, 4);
  NullProgress progress;
  FeatureMaskerOptions mask;
  mask.database_path = extract.database_path;
  mask.image_path = extract.image_path;
  RunFeatureMasker(mask, progress);
  {  // as an older portcal left it
    Database db(dir / "db.db", Database::OpenMode::kReadWrite);
    for (const DatabaseImage& image : db.ReadAllImages()) db.DeleteUnmaskedFeatures(image.image_id);
  }
  const std::string before = testing::ReadFileToString(dir / "db.db");
  mask.enlargement_factor = 5.0;
  try {
    RunFeatureMasker(mask, progress);
    FAIL() << "a wider mask over masked features went through";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const char* named :
         {"masked before", "enlargement factor 3", "feature_extractor --overwrite 1"}) {
      EXPECT_NE(what.find(named), std::string::npos) << named << ": " << what;
    }
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);
}

}  // namespace
}  // namespace portcal
