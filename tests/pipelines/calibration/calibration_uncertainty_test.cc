// Standard deviations that mean something: over 20 renders (40 for the
// camera) with different seeds, (estimate - truth) / reported std dev must have an RMS between 0.7
// and 1.4 for every estimated parameter — camera intrinsics, dome
// decentering, flat-port normal and distance (solved jointly with the
// camera's in-air views, so that the intrinsics' uncertainty is in them;
// and held on the in-air intrinsics with their covariance propagated, no
// |z| above 3), stereo relative pose.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/stereo_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/stages/synthesize.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr int kNumSeeds = 20;
// The camera's five intrinsics over 40 seeds: with 20 the RMS of a
// parameter's z-scores has a relative spread of 16 %, and one of five
// honest parameters lands outside 0.7-1.4 about one run in seven (seen:
// 0.67 for cy over seeds 1000-1019, 0.78 over 1000-1039).
constexpr int kNumCameraSeeds = 40;

struct Rendered {
  GroundTruth truth;
  TargetViews views;
};

// Renders the config with `seed`, extracts its chessboard (cols x rows,
// square metres), and frees the images.
Rendered RenderAndExtract(const fs::path& config, const fs::path& set, int64_t seed,
                          const std::string& model, int cols, int rows, double square,
                          bool per_folder = false) {
  SynthesizeOptions synthesize;
  synthesize.config_path = config.string();
  synthesize.output_path = set.string();
  synthesize.seed = seed;
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  TargetExtractorOptions extract;
  extract.database_path = (set / "db.db").string();
  extract.image_path = (set / "images").string();
  extract.reader.camera_model = model;
  extract.reader.single_camera = !per_folder;
  extract.reader.single_camera_per_folder = per_folder;
  extract.chessboard.cols = cols;
  extract.chessboard.rows = rows;
  extract.square_size_m = square;
  RunTargetExtractor(extract, progress);
  Rendered rendered;
  rendered.truth = ReadGroundTruth(set / "ground_truth.yaml");
  Database db(set / "db.db", Database::OpenMode::kReadOnly);
  rendered.views = ReadTargetViews(&db);
  fs::remove_all(set / "images");
  return rendered;
}

// z[i]: the normalized errors of parameter names[i] over the seeds.
void ExpectHonest(const std::vector<std::string>& names,
                  const std::vector<std::vector<double>>& z) {
  for (size_t i = 0; i < names.size(); ++i) {
    double sum = 0;
    for (double v : z[i]) sum += v * v;
    const double rms = std::sqrt(sum / z[i].size());
    std::cout << "z-score RMS of " << names[i] << ": " << rms << "\n";
    EXPECT_GT(rms, 0.7) << names[i];
    EXPECT_LT(rms, 1.4) << names[i];
  }
}

// The renders carry a lens's blur (0.5 px): without one, the renderer's 4 x 4
// stratified samples make each sharp edge a staircase no camera shows, which
// the corner fit's pixel-area model (rightly) does not follow.
TEST(CalibrationUncertainty, CameraStdDevsAreHonestAcrossSeeds) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: z_scores
num_images: 12
camera: {model: RADIAL, width: 800, height: 600, params: [700.0, 401.3, 298.7, -0.1, 0.02]}
housing: null
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, blur_sigma: 0.5, noise_sigma: 2.0}
)";
  std::vector<std::vector<double>> z(5);
  for (int seed = 0; seed < kNumCameraSeeds; ++seed) {
    const Rendered r = RenderAndExtract(dir / "set.yaml", dir / ("set" + std::to_string(seed)),
                                        1000 + seed, "RADIAL", 8, 6, 0.025);
    const CameraCalibrationResult result = CalibrateCamera(
        r.views.by_camera.begin()->second, Camera::FromModelName("RADIAL", 600, 800, 600), {});
    for (int i = 0; i < 5; ++i) {
      ASSERT_GT(result.params_std_dev[i], 0);
      z[i].push_back((result.camera.params[i] - r.truth.camera.params[i]) /
                     result.params_std_dev[i]);
    }
  }
  ExpectHonest({"f", "cx", "cy", "k1", "k2"}, z);
}

// A housing's set: the camera's in-air views and its underwater views
// (rendered with seeds `seed` and `seed` + 500), extracted.
struct HousingSets {
  Rendered in_air, underwater;
};

HousingSets RenderHousingSets(const fs::path& dir, const std::string& underwater_config,
                              int64_t seed, double square) {
  std::string in_air_config = underwater_config;
  const size_t housing = in_air_config.find("housing:");
  in_air_config.replace(housing, in_air_config.find('\n', housing) - housing, "housing: null");
  std::ofstream(dir / "air.yaml") << in_air_config;
  std::ofstream(dir / "water.yaml") << underwater_config;
  const std::string tag = std::to_string(seed);
  return {
      RenderAndExtract(dir / "air.yaml", dir / ("air" + tag), seed, "SIMPLE_RADIAL", 8, 6, square),
      RenderAndExtract(dir / "water.yaml", dir / ("water" + tag), seed + 500, "SIMPLE_RADIAL", 8, 6,
                       square)};
}

// The z-scores of the housing held on the in-air intrinsics, as
// housing_calibrator does with --input_calibration: with the lens's
// covariance propagated (`propagated`) and without (`exact`, the lens taken
// as exact).
struct HeldZScores {
  std::vector<double> propagated, exact;
};

// The housing solved jointly with the in-air views (intrinsics calibrated,
// not given), the board's warp fitted, as housing_calibrator does with
// --in_air_database_path; and, into `held`, on the in-air intrinsics held.
HousingCalibrationResult CalibrateJointly(const HousingSets& sets, const Housing& guess,
                                          HeldZScores* held, const std::vector<int>& params) {
  const auto& in_air_views = sets.in_air.views.by_camera.begin()->second;
  const auto& views = sets.underwater.views.by_camera.begin()->second;
  const CameraCalibrationResult in_air =
      CalibrateCamera(in_air_views,
                      Camera::FromModelName("SIMPLE_RADIAL", 500, sets.in_air.truth.camera.width,
                                            sets.in_air.truth.camera.height),
                      {});
  HousingCalibrationSettings settings;
  settings.estimate_board_warp = true;
  const HousingCalibrationResult propagated =
      CalibrateHousing(views, in_air.camera, guess, settings, nullptr, &in_air.params_covariance);
  EXPECT_TRUE(propagated.lens_covariance_propagated);
  const HousingCalibrationResult exact = CalibrateHousing(views, in_air.camera, guess, settings);
  for (int i : params) {
    const double error = propagated.housing.params[i] - sets.underwater.truth.housing->params[i];
    held->propagated.push_back(error / propagated.housing_std_dev[i]);
    held->exact.push_back((exact.housing.params[i] - sets.underwater.truth.housing->params[i]) /
                          exact.housing_std_dev[i]);
  }
  const InAirViews joint{
      in_air_views, /*share_board_warp=*/false, {}};  // each set's own sag, the default
  return CalibrateHousing(views, in_air.camera, guess, settings, &joint);
}

// Appends the z-scores of the housing's `params` and of the focal length.
void AddZScores(const HousingCalibrationResult& result, const HousingSets& sets,
                const std::vector<int>& params, std::vector<std::vector<double>>* z) {
  for (size_t k = 0; k < params.size(); ++k) {
    const int i = params[k];
    ASSERT_GT(result.housing_std_dev[i], 0);
    (*z)[k].push_back((result.housing.params[i] - sets.underwater.truth.housing->params[i]) /
                      result.housing_std_dev[i]);
  }
  (*z)[params.size()].push_back((result.camera.params[0] - sets.in_air.truth.camera.params[0]) /
                                result.camera_std_dev[0]);
}

void PrintRms(const std::string& what, const std::vector<double>& z) {
  double sum = 0, max = 0;
  for (double v : z) sum += v * v, max = std::max(max, std::abs(v));
  std::cout << "z-score RMS of " << what << ": " << std::sqrt(sum / z.size()) << " (max |z| " << max
            << ")\n";
}

// The held path's propagated standard deviations: honest over all the
// housing's parameters together (the issue's bound: RMS 0.7-1.4, no |z|
// above 3), and the lens taken as exact printed beside, for the record.
void ExpectHeldHonest(const std::string& what, const HeldZScores& held) {
  double sum = 0;
  for (double z : held.propagated) {
    sum += z * z;
    EXPECT_LE(std::abs(z), 3.0) << what;
  }
  const double rms = std::sqrt(sum / held.propagated.size());
  EXPECT_GT(rms, 0.7) << what;
  EXPECT_LT(rms, 1.4) << what;
  PrintRms(what + " with the in-air intrinsics held, their covariance propagated", held.propagated);
  PrintRms(what + " with the in-air intrinsics held as exact", held.exact);
}

// The dome's decentering with its standard deviations from the joint solve.
TEST(CalibrationUncertainty, DomeStdDevsIncludeTheInAirCalibration) {
  testing::TempDir dir;
  const std::string config = R"(name: z_scores_dome
num_images: 10
camera: {model: SIMPLE_RADIAL, width: 640, height: 480, params: [560.0, 323.0, 236.5, -0.05]}
housing: {model: DOMEPORT, params: [0.006, -0.004, 0.008, 0.05, 0.006, 1.0, 1.473, 1.334]}
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, blur_sigma: 0.5, noise_sigma: 2.0}
)";
  std::vector<std::vector<double>> z(4);
  HeldZScores held;
  for (int seed = 0; seed < kNumSeeds; ++seed) {
    const HousingSets sets = RenderHousingSets(dir.path(), config, 2000 + seed, 0.025);
    Housing guess = *sets.underwater.truth.housing;
    guess.params[0] = guess.params[1] = guess.params[2] = 0;
    AddZScores(CalibrateJointly(sets, guess, &held, {0, 1, 2}), sets, {0, 1, 2}, &z);
  }
  ExpectHonest({"Cx", "Cy", "Cz", "f"}, z);
  ExpectHeldHonest("Cx, Cy, Cz", held);
}

// The flat port's normal (Nx, Ny: to first order its tangent angles) and
// distance, from the joint solve.
TEST(CalibrationUncertainty, FlatPortStdDevsIncludeTheInAirCalibration) {
  testing::TempDir dir;
  const std::string config = R"(name: z_scores_flat
num_images: 10
camera: {model: SIMPLE_RADIAL, width: 640, height: 480, params: [500.0, 316.0, 243.0, -0.05]}
housing: {model: FLATPORT, params: [0.0523360, -0.0348782, 0.9980203, 0.03, 0.012, 1.0, 1.49, 1.334]}
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.4, 1.0], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, blur_sigma: 0.5, noise_sigma: 2.0}
)";
  std::vector<std::vector<double>> z(4);
  HeldZScores held;
  for (int seed = 0; seed < kNumSeeds; ++seed) {
    const HousingSets sets = RenderHousingSets(dir.path(), config, 3000 + seed, 0.03);
    Housing guess = *sets.underwater.truth.housing;
    guess.params[0] = 0;
    guess.params[1] = 0;
    guess.params[2] = 1;
    guess.params[3] = 0.05;
    AddZScores(CalibrateJointly(sets, guess, &held, {0, 1, 3}), sets, {0, 1, 3}, &z);
  }
  ExpectHonest({"Nx", "Ny", "int_dist", "f"}, z);
  ExpectHeldHonest("Nx, Ny, int_dist", held);
}

// A stereo rig's relative pose, the intrinsics given.
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
  std::vector<std::vector<double>> z(6);
  for (int seed = 0; seed < kNumSeeds; ++seed) {
    const Rendered r =
        RenderAndExtract(dir / "set.yaml", dir / ("set" + std::to_string(seed)), 4000 + seed,
                         "SIMPLE_RADIAL", 9, 6, 0.025, /*per_folder=*/true);
    ASSERT_EQ(r.views.by_camera.size(), 2u);
    const auto& views1 = r.views.by_camera.begin()->second;
    const auto& views2 = std::next(r.views.by_camera.begin())->second;
    std::vector<StereoFrame> frames;
    for (size_t i = 0; i < std::min(views1.size(), views2.size()); ++i)
      frames.push_back({views1[i], views2[i]});
    const StereoCalibrationResult result = CalibrateStereo(
        frames, {r.truth.camera, std::nullopt}, {r.truth.stereo->camera2, std::nullopt}, {});
    // Rotation error as the rotation vector of est * truth^-1 (Ceres'
    // quaternion manifold perturbs on the left), in degrees.
    const Eigen::AngleAxisd delta(result.cam2_from_cam1.rotation *
                                  r.truth.stereo->cam2_from_cam1.rotation.inverse());
    const Eigen::Vector3d rotation_error = delta.angle() * delta.axis() * 180 / M_PI;
    const Eigen::Vector3d translation_error =
        result.cam2_from_cam1.translation - r.truth.stereo->cam2_from_cam1.translation;
    for (int i = 0; i < 3; ++i) {
      ASSERT_GT(result.rotation_std_dev_deg[i], 0);
      z[i].push_back(rotation_error[i] / result.rotation_std_dev_deg[i]);
      z[3 + i].push_back(translation_error[i] / result.translation_std_dev[i]);
    }
  }
  ExpectHonest({"rx", "ry", "rz", "tx", "ty", "tz"}, z);
}

}  // namespace
}  // namespace portcal
