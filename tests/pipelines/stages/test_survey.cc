#include "tests/pipelines/stages/test_survey.h"

#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_matcher.h"
#include "pipelines/stages/pose_prior_importer.h"

namespace portcal {
namespace testing {

MatchedSurvey RenderAndMatchTestSurvey(const TempDir& dir, const std::string& survey_keys) {
  MatchedSurvey survey;
  survey.truth = RenderSet(dir, R"(name: survey
num_images: 48
camera: {model: RADIAL, width: 640, height: 360, params: [466.7, 320.0, 180.0, 0.0, 0.0]}
housing: {model: FLATPORT, params: [0.0523360, 0.0, 0.9986295, 0.02, 0.010, 1.0, 1.473, 1.334]}
survey: {height: 2.0, speed: 0.5, frame_rate: 1.0, side_overlap: 0.6, line_length: 6.0,
         roughness: 0.15, relief_wavelength: 2.0, navigation_sigma: 0.02)" +
                                    survey_keys + R"(}
render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)");
  survey.database = (dir / "db.db").string();
  survey.image_path = (dir / "set" / "images").string();
  FeatureExtractorOptions extract;
  extract.database_path = survey.database;
  extract.image_path = survey.image_path;
  extract.reader.single_camera = true;
  extract.reader.camera_model = "RADIAL";
  extract.reader.camera_params = "466.7,320,180,0,0";
  extract.sift.max_num_features = 1500;
  RunFeatureExtractor(extract, NoProgress());
  PosePriorImporterOptions priors;
  priors.database_path = survey.database;
  priors.input_path = (dir / "set" / "navigation.txt").string();
  survey.num_position_priors = RunPosePriorImporter(priors, NoProgress()).num_imported;
  FeatureMatcherOptions match;
  match.database_path = survey.database;
  match.mode = PairingMode::kSpatial;
  match.spatial.max_num_neighbors = 10;
  RunFeatureMatcher(match, NoProgress());
  return survey;
}

}  // namespace testing
}  // namespace portcal
