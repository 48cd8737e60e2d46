// Standard deviations that mean something: over 20 renders with different
// seeds, (estimate - truth) / reported std dev must have an RMS between 0.7
// and 1.4 for every estimated parameter.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/stereo_calibration.h"
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

namespace portcal {
namespace {

// And for a flat port's normal (tangent angles) and distance.
TEST(CalibrationUncertainty, FlatPortStdDevsAreHonestAcrossSeeds) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: z_scores_flat
num_images: 10
camera: {model: SIMPLE_RADIAL, width: 640, height: 480, params: [500.0, 320.0, 240.0, -0.05]}
housing: {model: FLATPORT, params: [0.0523360, -0.0348782, 0.9980203, 0.03, 0.012, 1.0, 1.49, 1.334]}
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.4, 1.0], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 2.0}
)";
  const int num_seeds = 20;
  std::vector<std::vector<double>> z(3);
  for (int seed = 0; seed < num_seeds; ++seed) {
    const fs::path set = dir / ("set" + std::to_string(seed));
    SynthesizeOptions synthesize;
    synthesize.config_path = (dir / "set.yaml").string();
    synthesize.output_path = set.string();
    synthesize.seed = 3000 + seed;
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
    extract.square_size_m = 0.03;
    ExtractTargets(extract, progress);
    Database db(set / "db.db", Database::OpenMode::kReadOnly);
    Housing guess = *truth.housing;
    guess.params[0] = 0;
    guess.params[1] = 0;
    guess.params[2] = 1;
    guess.params[3] = 0.05;
    const HousingCalibrationResult result =
        CalibrateHousing(ReadTargetViews(&db).by_camera.begin()->second, truth.camera, guess, {});
    // Nx and Ny are (to first order) the normal's two tangent angles.
    for (int i : {0, 1, 3}) {
      ASSERT_GT(result.housing_std_dev[i], 0);
    }
    z[0].push_back((result.housing.params[0] - truth.housing->params[0]) / result.housing_std_dev[0]);
    z[1].push_back((result.housing.params[1] - truth.housing->params[1]) / result.housing_std_dev[1]);
    z[2].push_back((result.housing.params[3] - truth.housing->params[3]) / result.housing_std_dev[3]);
    fs::remove_all(set / "images");
  }
  const char* names[] = {"Nx", "Ny", "int_dist"};
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

namespace portcal {
namespace {

// And for a stereo rig's relative pose (intrinsics given).
TEST(CalibrationUncertainty, StereoStdDevsAreHonestAcrossSeeds) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: z_scores_stereo
num_images: 8
camera: {model: SIMPLE_RADIAL, width: 640, height: 480, params: [520.0, 320.0, 240.0, -0.04]}
housing: null
stereo:
  cam2_from_cam1: {rotation_axis_angle_deg: [0.1, 1.0, 0.0, -5.0], translation: [-0.1, 0.002, 0.006]}
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.4, 0.9], tilt_max_deg: 40, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 2.0}
)";
  const int num_seeds = 20;
  std::vector<std::vector<double>> z(6);
  for (int seed = 0; seed < num_seeds; ++seed) {
    const fs::path set = dir / ("set" + std::to_string(seed));
    SynthesizeOptions synthesize;
    synthesize.config_path = (dir / "set.yaml").string();
    synthesize.output_path = set.string();
    synthesize.seed = 4000 + seed;
    NullProgress progress;
    Synthesize(synthesize, progress);
    const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
    TargetExtractorOptions extract;
    extract.database_path = (set / "db.db").string();
    extract.image_path = (set / "images").string();
    extract.reader.camera_model = "SIMPLE_RADIAL";
    extract.reader.single_camera_per_folder = true;
    extract.chessboard.cols = 9;
    extract.chessboard.rows = 6;
    extract.square_size_m = 0.025;
    ExtractTargets(extract, progress);
    Database db(set / "db.db", Database::OpenMode::kReadOnly);
    const TargetViews views = ReadTargetViews(&db);
    ASSERT_EQ(views.by_camera.size(), 2u);
    const auto& views1 = views.by_camera.begin()->second;
    const auto& views2 = std::next(views.by_camera.begin())->second;
    std::vector<StereoFrame> frames;
    for (size_t i = 0; i < std::min(views1.size(), views2.size()); ++i) frames.push_back({views1[i], views2[i]});
    const StereoCalibrationResult result =
        CalibrateStereo(frames, {truth.camera, std::nullopt}, {truth.stereo->camera2, std::nullopt}, {});
    // Rotation error as the rotation vector of est * truth^-1 (Ceres'
    // quaternion manifold perturbs on the left), in degrees.
    const Eigen::AngleAxisd delta(result.cam2_from_cam1.rotation * truth.stereo->cam2_from_cam1.rotation.inverse());
    const Eigen::Vector3d rotation_error = delta.angle() * delta.axis() * 180 / M_PI;
    const Eigen::Vector3d translation_error =
        result.cam2_from_cam1.translation - truth.stereo->cam2_from_cam1.translation;
    for (int i = 0; i < 3; ++i) {
      ASSERT_GT(result.rotation_std_dev_deg[i], 0);
      z[i].push_back(rotation_error[i] / result.rotation_std_dev_deg[i]);
      z[3 + i].push_back(translation_error[i] / result.translation_std_dev[i]);
    }
    fs::remove_all(set / "images");
  }
  const char* names[] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  for (int i = 0; i < 6; ++i) {
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
