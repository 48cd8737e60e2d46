// Standard deviations that mean something: over 20 renders with different
// seeds, (estimate - truth) / reported std dev must have an RMS between 0.7
// and 1.4 for every estimated parameter.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/synthesize/synthesize.h"
#include "pipelines/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

TEST(CalibrationUncertainty, CameraStdDevsAreHonestAcrossSeeds) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: z_scores
num_images: 12
camera: {model: RADIAL, width: 800, height: 600, params: [700.0, 401.3, 298.7, -0.1, 0.02]}
housing: null
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 2.0}
)";
  const int num_seeds = 20;
  std::vector<std::vector<double>> z(5);
  for (int seed = 0; seed < num_seeds; ++seed) {
    const fs::path set = dir / ("set" + std::to_string(seed));
    SynthesizeOptions synthesize;
    synthesize.config_path = (dir / "set.yaml").string();
    synthesize.output_path = set.string();
    synthesize.seed = 1000 + seed;
    NullProgress progress;
    Synthesize(synthesize, progress);
    const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");

    TargetExtractorOptions extract;
    extract.database_path = (set / "db.db").string();
    extract.image_path = (set / "images").string();
    extract.reader.camera_model = "RADIAL";
    extract.reader.single_camera = true;
    extract.chessboard.cols = 8;
    extract.chessboard.rows = 6;
    extract.square_size_m = 0.025;
    ExtractTargets(extract, progress);
    Database db(set / "db.db", Database::OpenMode::kReadOnly);
    const std::vector<CalibrationView> views = ReadTargetViews(&db).by_camera.begin()->second;
    const Camera initial = Camera::FromModelName("RADIAL", 600, 800, 600);
    const CameraCalibrationResult result = CalibrateCamera(views, initial, {});
    for (int i = 0; i < 5; ++i) {
      ASSERT_GT(result.params_std_dev[i], 0);
      z[i].push_back((result.camera.params[i] - truth.camera.params[i]) / result.params_std_dev[i]);
    }
    fs::remove_all(set / "images");
  }
  const char* names[] = {"f", "cx", "cy", "k1", "k2"};
  for (int i = 0; i < 5; ++i) {
    double sum = 0;
    for (double v : z[i]) sum += v * v;
    const double rms = std::sqrt(sum / z[i].size());
    RecordProperty(names[i], std::to_string(rms));
    std::cout << "z-score RMS of " << names[i] << ": " << rms << "\n";
    EXPECT_GT(rms, 0.7) << names[i];
    EXPECT_LT(rms, 1.4) << names[i];
  }
}

}  // namespace
}  // namespace portcal

namespace portcal {
namespace {

// The same for a dome port's decentering, the intrinsics given exactly.
TEST(CalibrationUncertainty, DomeStdDevsAreHonestAcrossSeeds) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: z_scores_dome
num_images: 10
camera: {model: SIMPLE_RADIAL, width: 640, height: 480, params: [560.0, 320.0, 240.0, -0.05]}
housing: {model: DOMEPORT, params: [0.006, -0.004, 0.008, 0.05, 0.006, 1.0, 1.473, 1.334]}
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 2.0}
)";
  const int num_seeds = 20;
  std::vector<std::vector<double>> z(3);
  for (int seed = 0; seed < num_seeds; ++seed) {
    const fs::path set = dir / ("set" + std::to_string(seed));
    SynthesizeOptions synthesize;
    synthesize.config_path = (dir / "set.yaml").string();
    synthesize.output_path = set.string();
    synthesize.seed = 2000 + seed;
    NullProgress progress;
    Synthesize(synthesize, progress);
    const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
    TargetExtractorOptions extract;
    extract.database_path = (set / "db.db").string();
    extract.image_path = (set / "images").string();
    extract.reader.camera_model = "SIMPLE_RADIAL";
    extract.reader.single_camera = true;
    extract.chessboard.cols = 8;
    extract.chessboard.rows = 6;
    extract.square_size_m = 0.025;
    ExtractTargets(extract, progress);
    Database db(set / "db.db", Database::OpenMode::kReadOnly);
    Housing guess = *truth.housing;
    guess.params[0] = guess.params[1] = guess.params[2] = 0;
    const HousingCalibrationResult result =
        CalibrateHousing(ReadTargetViews(&db).by_camera.begin()->second, truth.camera, guess, {});
    for (int i = 0; i < 3; ++i) {
      ASSERT_GT(result.housing_std_dev[i], 0);
      z[i].push_back((result.housing.params[i] - truth.housing->params[i]) / result.housing_std_dev[i]);
    }
    fs::remove_all(set / "images");
  }
  const char* names[] = {"Cx", "Cy", "Cz"};
  for (int i = 0; i < 3; ++i) {
    double sum = 0;
    for (double v : z[i]) sum += v * v;
    const double rms = std::sqrt(sum / z[i].size());
    std::cout << "z-score RMS of " << names[i] << ": " << rms << "\n";
    EXPECT_GT(rms, 0.7) << names[i];
    EXPECT_LT(rms, 1.4) << names[i];
  }
}

}  // namespace
}  // namespace portcal
