// feature_masker reruns: the same mask again changes nothing; another mask
// over masked features is refused with the reason and the way out, the
// database untouched; after the features are extracted again, it applies.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_masker.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

TEST(FeatureMasker, AnotherMaskOverMaskedFeaturesIsRefusedWithTheReason) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml")
      << "name: mask\nnum_images: 3\nseed: 3\n"
      << "camera: {model: RADIAL, width: 480, height: 270, params: [330.0, 240.0, 135.0, 0.0, 0.0]}\n"
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
  FeatureMaskerOptions mask;
  mask.database_path = extract.database_path;
  mask.image_path = extract.image_path;
  mask.enlargement_factor = 3.0;
  const FeatureMaskerSummary first = RunFeatureMasker(mask, progress);
  ASSERT_LT(first.num_features_kept, first.num_features_before);
  const FeatureMaskerSummary again = RunFeatureMasker(mask, progress);
  EXPECT_EQ(again.num_features_kept, first.num_features_kept);
  EXPECT_EQ(again.num_features_before, first.num_features_kept);

  const std::string before = testing::ReadFileToString(dir / "db.db");
  mask.enlargement_factor = 5.0;
  try {
    RunFeatureMasker(mask, progress);
    FAIL() << "a wider mask over masked features went through";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const char* named : {"masked before", "enlargement factor 3", "feature_extractor --overwrite 1"}) {
      EXPECT_NE(what.find(named), std::string::npos) << named << ": " << what;
    }
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);

  extract.overwrite = true;
  RunFeatureExtractor(extract, progress);
  const FeatureMaskerSummary wider = RunFeatureMasker(mask, progress);
  EXPECT_EQ(wider.num_features_before, first.num_features_before);
  EXPECT_GT(wider.num_features_kept, first.num_features_kept);
}

}  // namespace
}  // namespace portcal
