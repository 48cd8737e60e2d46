// Auto-calibration end to end (extract -> mask -> match -> refractive mapper
// -> refine) against ground truth: on portcal's own small renders (flat port,
// dome and in air, intrinsics unknown) and on the shared rendered 3-D target
// sets (full size; skipped without ../shared). Tolerances: the reported
// standard deviation times 4 (a 4-sigma bound), and the issue's absolute
// goals where portcal meets them; where it does not yet, the bound asserted
// is the measured level plus a margin, and the gap is stated.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/io/sparse_model.h"
#include "database/database.h"
#include "pipelines/stages/auto_calibrator.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr double kDegree = M_PI / 180.0;

const char* kViews =
    R"(poses: {distance: [0.4, 1.0], tilt_max_deg: 45, roll_max_deg: 180, visibility: markers, border_margin_px: 10, max_view_angle_deg: 70}
render: {spp: 4, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)";

GroundTruth Render(const fs::path& dir, const std::string& camera_and_housing) {
  std::ofstream(dir / "set.yaml") << "name: auto\nnum_images: 15\n"
                                  << camera_and_housing << testing::kTwoFaceTargetYaml << kViews;
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  return ReadGroundTruth(dir / "set" / "ground_truth.yaml");
}

AutoCalibratorSummary Calibrate(const fs::path& images, const fs::path& out,
                                const std::string& housing_model, const std::string& housing_guess,
                                const std::string& camera_params = "",
                                bool update_database = false) {
  AutoCalibratorOptions options;
  options.camera_params = camera_params;
  options.update_database = update_database;
  options.image_path = images.string();
  options.output_path = out.string();
  options.housing = HousingFromText(housing_model, housing_guess);
  options.marker_scale.side_length_m = 0.06;
  NullProgress progress;
  return RunAutoCalibrator(options, progress);
}

// An own render of 15 views in `dir`, auto-calibrated; all views register.
struct OwnRun {
  GroundTruth truth;
  AutoCalibratorSummary result;
};

OwnRun RenderAndCalibrate(const fs::path& dir, const std::string& camera_and_housing,
                          const std::string& housing_model, const std::string& housing_guess,
                          bool update_database = false) {
  OwnRun run;
  run.truth = Render(dir, camera_and_housing);
  run.result = Calibrate(dir / "set" / "images", dir / "out", housing_model, housing_guess, "",
                         update_database);
  EXPECT_EQ(run.result.num_registered, 15);
  return run;
}

double NormalAngle(const std::vector<double>& a, const std::vector<double>& b) {
  const Eigen::Vector3d na(a[0], a[1], a[2]), nb(b[0], b[1], b[2]);
  return std::acos(std::min(1.0, na.normalized().dot(nb.normalized())));
}

// Angular std dev of the normal from the std devs of its components
// (tangent plane: the two components across it).
double NormalSigma(const std::vector<double>& std_dev) {
  return std::sqrt(std_dev[0] * std_dev[0] + std_dev[1] * std_dev[1] + std_dev[2] * std_dev[2]);
}

// The report's notes and warnings that contain `text`.
std::vector<std::string> NotesWith(const CalibrationReport& r, const std::string& text) {
  std::vector<std::string> found;
  for (const auto* lines : {&r.warnings, &r.notes}) {
    for (const std::string& line : *lines) {
      std::cout << (lines == &r.warnings ? "warning: " : "note: ") << line << "\n";
      if (line.find(text) != std::string::npos) found.push_back(line);
    }
  }
  return found;
}

// An off-centre principal point: refined (the report says so), within 4
// sigma of the truth.
void ExpectPrincipalPointRefined(const CalibrationReport& r, const GroundTruth& truth) {
  for (int i : {1, 2}) {
    EXPECT_GT(r.parameters_std_dev[i], 0.0) << "the principal point was held";
    EXPECT_LT(std::abs(r.camera.params[i] - truth.camera.params[i]), 4 * r.parameters_std_dev[i]);
  }
  EXPECT_EQ(NotesWith(r, "principal point refined").size(), 1u);
}

// Images without markers: the run fails (the masker finds none) and takes
// with it what it made: no output folder, no database left behind.
TEST(AutoCalibration, AFailedRunLeavesNoOutputBehind) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((dir / ("images/img_" + std::to_string(i) + ".png")).string(),
                testing::ClutteredScene(320, 240, i));
  }
  EXPECT_ANY_THROW(
      Calibrate(dir / "images", dir / "out", "FLATPORT", "0,0,1,0.015,0.010,1,1.473,1.334"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(AutoCalibration, OwnRenderFlatPortIntrinsicsUnknown) {
  // The principal point 4 px and 3.5 px off the image centre: held at the
  // centre it would be absorbed by the port's tilt and distance.
  testing::TempDir dir;
  const OwnRun run = RenderAndCalibrate(
      dir.path(),
      R"(camera: {model: RADIAL, width: 960, height: 540, params: [650.0, 484.0, 266.5, 0.0, 0.0]}
housing: {model: FLATPORT, params: [0.0697565, 0.0, 0.9975641, 0.015, 0.010, 1.0, 1.473, 1.334]}
)",
      "FLATPORT", "0,0,1,0.015,0.010,1,1.473,1.334", true);
  const GroundTruth& truth = run.truth;
  const CalibrationReport& r = run.result.refined.report;
  ASSERT_TRUE(r.housing);
  {  // --update_database: the calibration is the database's camera and housing now
    Database db(dir / "out" / "database.db", Database::OpenMode::kReadOnly);
    const std::vector<Camera> cameras = db.ReadAllCameras();
    ASSERT_EQ(cameras.size(), 1u);
    EXPECT_EQ(cameras[0].params, r.camera.params);
    const std::optional<Housing> housing = db.ReadHousing(cameras[0].camera_id);
    ASSERT_TRUE(housing);
    EXPECT_EQ(housing->params, r.housing->params);
  }
  const double df = std::abs(r.camera.params[0] - truth.camera.params[0]);
  const double angle = NormalAngle(r.housing->params, truth.housing->params);
  const double dd = std::abs(r.housing->params[3] - truth.housing->params[3]);
  std::cout << "own flat: |df| " << df << " px (sd " << r.parameters_std_dev[0] << "), normal "
            << angle / kDegree << " deg (sd " << NormalSigma(r.housing_std_dev) / kDegree
            << "), |dd| " << dd * 1000 << " mm (sd " << r.housing_std_dev[3] * 1000 << ")\n";
  EXPECT_LT(df, 4 * r.parameters_std_dev[0]);
  EXPECT_LT(angle, 4 * NormalSigma(r.housing_std_dev));
  EXPECT_LT(dd, 4 * r.housing_std_dev[3]);
  EXPECT_LT(dd, 0.003);  // with marker scale, metres are metres
  ExpectPrincipalPointRefined(r, truth);
  // The sparse model is COLMAP's, with the housing beside it.
  const SparseModel model = ReadSparseModel(dir / "out" / "refined");
  EXPECT_EQ(model.images.size(), 15u);
  EXPECT_EQ(model.housings.size(), 1u);
  // The views' poses are in the reconstruction's frame: there is no target.
  const std::string yaml = testing::ReadFileToString(dir / "out" / "calibration.yaml");
  EXPECT_NE(yaml.find("cam_from_world:"), std::string::npos);
  EXPECT_EQ(yaml.find("cam_from_target"), std::string::npos);
  // The page with the reconstruction from above beside the reports
  // (report_page_test loads such a page in a browser).
  const std::string page = testing::ReadFileToString(dir / "out" / "report.html");
  for (const char* picture :
       {"scene.png", "coverage.png", "per_view_rms.png", "residuals.png", "housing.png"}) {
    EXPECT_NE(page.find(picture), std::string::npos) << picture;
    EXPECT_TRUE(fs::exists(dir / "out" / picture)) << picture;
  }
}

TEST(AutoCalibration, OwnRenderWhoseBestPairStartsAWrongModel) {
  // Seed 11 of workflows/bench_autocal_seeds.sh (12 views): the pair with
  // the most matches, two nearly frontal views 13 deg apart, gives a
  // relative pose on the wrong side of the bas-relief ambiguity, and the
  // model grown from it had implausible intrinsics at every refinement
  // (f ~1300 px for 650); refining it threw. The mapper now builds the
  // model again from the next pair. Its port then sat at the distance's
  // floor, from where the refinement now starts it at the guess's
  // distance, the intrinsics first.
  testing::TempDir dir;
  std::ofstream(dir.path() / "set.yaml")
      << "name: seed11\nnum_images: 12\n"
      << R"(camera: {model: RADIAL, width: 960, height: 540, params: [650.0, 484.0, 266.5, 0.0, 0.0]}
housing: {model: FLATPORT, params: [0.0697565, 0.0, 0.9975641, 0.015, 0.010, 1.0, 1.473, 1.334]}
)" << testing::kTwoFaceTargetYaml
      << kViews;
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir.path() / "set.yaml").string();
  synthesize.output_path = (dir.path() / "set").string();
  synthesize.seed = 11;
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  const GroundTruth truth = ReadGroundTruth(dir.path() / "set" / "ground_truth.yaml");
  const AutoCalibratorSummary result = Calibrate(dir.path() / "set" / "images", dir.path() / "out",
                                                 "FLATPORT", "0,0,1,0.015,0.010,1,1.473,1.334");
  EXPECT_EQ(result.num_registered, 12);
  const CalibrationReport& r = result.refined.report;
  ASSERT_TRUE(r.housing);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  const double df = r.camera.params[0] - truth.camera.params[0];
  const double dd = r.housing->params[3] - truth.housing->params[3];
  std::cout << "seed 11: df " << df << " px (sd " << r.parameters_std_dev[0] << "), dd "
            << dd * 1000 << " mm (sd " << r.housing_std_dev[3] * 1000 << ")\n";
  EXPECT_LT(std::abs(df), 4 * r.parameters_std_dev[0]);
  EXPECT_LT(std::abs(dd), 4 * r.housing_std_dev[3]);
  EXPECT_LT(NormalAngle(r.housing->params, truth.housing->params),
            4 * NormalSigma(r.housing_std_dev));
}

TEST(AutoCalibration, OwnRenderDomePortPrincipalPointOffCentre) {
  // A dome's lateral decentering and the principal point move the rays
  // alike (only depth tells them apart): with the principal point held at
  // the image centre 4 px away, the decentering (and the focal length)
  // would take up the offset.
  testing::TempDir dir;
  const OwnRun run = RenderAndCalibrate(
      dir.path(),
      R"(camera: {model: RADIAL, width: 960, height: 540, params: [650.0, 476.0, 273.0, -0.05, 0.0]}
housing: {model: DOMEPORT, params: [-0.004, 0.006, -0.008, 0.05, 0.006, 1.0, 1.473, 1.334]}
)",
      "DOMEPORT", "0,0,0,0.05,0.006,1,1.473,1.334");
  const GroundTruth& truth = run.truth;
  const CalibrationReport& r = run.result.refined.report;
  ASSERT_TRUE(r.housing);
  const double df = std::abs(r.camera.params[0] - truth.camera.params[0]);
  std::cout << "own dome: |df| " << df << " px (sd " << r.parameters_std_dev[0] << "), dc ("
            << r.camera.params[1] - truth.camera.params[1] << ", "
            << r.camera.params[2] - truth.camera.params[2] << ") px, dC ("
            << (r.housing->params[0] - truth.housing->params[0]) * 1000 << ", "
            << (r.housing->params[1] - truth.housing->params[1]) * 1000 << ", "
            << (r.housing->params[2] - truth.housing->params[2]) * 1000 << ") mm\n";
  EXPECT_LT(df, 4 * r.parameters_std_dev[0]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(r.housing->params[k] - truth.housing->params[k]), 4 * r.housing_std_dev[k])
        << "C" << k;
  }
  ExpectPrincipalPointRefined(r, truth);
}

TEST(AutoCalibration, OwnRenderDomeDecentredAlongItsAxisReportsTheFocalLengthTrade) {
  // Decentred along its axis, a dome magnifies like a longer focal length:
  // with the intrinsics unknown, the views tell f from Cz only by small
  // higher-order effects. The report must say so, with the factor by which
  // the intrinsics inflate Cz's standard deviation, and the standard
  // deviations must cover the errors; given the intrinsics, Cz's standard
  // deviation must shrink by that factor and the note go.
  testing::TempDir dir;
  const OwnRun run = RenderAndCalibrate(
      dir.path(),
      R"(camera: {model: RADIAL, width: 960, height: 540, params: [750.0, 476.0, 273.0, 0.0, 0.0]}
housing: {model: DOMEPORT, params: [0.001, -0.001, 0.010, 0.06, 0.008, 1.0, 1.52, 1.334]}
)",
      "DOMEPORT", "0,0,0,0.06,0.008,1,1.52,1.334");
  const GroundTruth& truth = run.truth;
  const CalibrationReport& r = run.result.refined.report;
  ASSERT_TRUE(r.housing);
  const double df = r.camera.params[0] - truth.camera.params[0];
  const double dcz = r.housing->params[2] - truth.housing->params[2];
  std::cout << "own axial dome: df " << df << " px (sd " << r.parameters_std_dev[0] << "), dCz "
            << dcz * 1000 << " mm (sd " << r.housing_std_dev[2] * 1000 << ")\n";
  EXPECT_LT(std::abs(df), 4 * r.parameters_std_dev[0]);
  EXPECT_LT(std::abs(dcz), 4 * r.housing_std_dev[2]);
  const std::vector<std::string> trade = NotesWith(r, "f and Cz are correlated");
  ASSERT_EQ(trade.size(), 1u);
  const size_t at = trade[0].find("at least ");
  ASSERT_NE(at, std::string::npos);
  const double factor = std::stod(trade[0].substr(at + 9));
  EXPECT_GT(factor, 3.2);  // |rho| >= 0.95

  std::ostringstream intrinsics;
  for (size_t i = 0; i < truth.camera.params.size(); ++i)
    intrinsics << (i ? "," : "") << truth.camera.params[i];
  const AutoCalibratorSummary given =
      Calibrate(dir.path() / "set" / "images", dir.path() / "given", "DOMEPORT",
                "0,0,0,0.06,0.008,1,1.52,1.334", intrinsics.str());
  const CalibrationReport& g = given.refined.report;
  ASSERT_TRUE(g.housing);
  const double dcz_given = g.housing->params[2] - truth.housing->params[2];
  std::cout << "own axial dome, intrinsics given: dCz " << dcz_given * 1000 << " mm (sd "
            << g.housing_std_dev[2] * 1000 << "; by the noise "
            << g.housing_std_dev_by_noise.at(2) * 1000 << ", by the clusters "
            << g.housing_std_dev_by_clusters.at(2) * 1000 << ")\n";
  EXPECT_TRUE(NotesWith(g, "correlated").empty());
  // The factor is that of f alone and of the first run's solution, from
  // the noise model's covariance: within a factor 2 of that model's sd with
  // all intrinsics given in a second run.
  const double sd_unknown = r.housing_std_dev_by_noise.at(2),
               sd_given = g.housing_std_dev_by_noise.at(2);
  EXPECT_LT(sd_given, 2 * sd_unknown / factor);
  EXPECT_GT(sd_given, 0.5 * sd_unknown / factor);
  // The reported sd covers the error (by the noise alone it did not: 1.8 mm
  // off at 0.44 mm, 4.1 sigma; the images' spread says 1.35 mm).
  EXPECT_LT(std::abs(dcz_given), 4 * g.housing_std_dev[2]);
}

TEST(AutoCalibration, OwnRenderInAirWithoutIntrinsics) {
  // The published tool fails outright here ("can not estimate pose of image
  // 0"); the markers pre-calibrate the focal length.
  testing::TempDir dir;
  const OwnRun run = RenderAndCalibrate(
      dir.path(),
      R"(camera: {model: RADIAL, width: 960, height: 540, params: [700.0, 480.0, 270.0, -0.04, 0.0]}
housing: null
)",
      "", "");
  const GroundTruth& truth = run.truth;
  const CalibrationReport& r = run.result.refined.report;
  EXPECT_FALSE(r.housing);
  const double df = std::abs(r.camera.params[0] - truth.camera.params[0]);
  const double dk1 = std::abs(r.camera.params[3] - truth.camera.params[3]);
  std::cout << "own air: |df| " << df << " px (sd " << r.parameters_std_dev[0] << "), |dk1| " << dk1
            << " (sd " << r.parameters_std_dev[3] << ")\n";
  EXPECT_LT(df, std::max(1.0, 4 * r.parameters_std_dev[0]));
  EXPECT_LT(dk1, 4 * r.parameters_std_dev[3]);
  // The principal point is at the image centre: refined, it stays within
  // 3 sigma of it (but for 1 run in ~200) and is then held there.
  ASSERT_EQ(r.notes.size(), 1u);
  std::cout << "own air: " << r.notes[0] << "\n";
  if (r.notes[0].find("held") != std::string::npos) {
    EXPECT_EQ(r.camera.params[1], 480.0);
    EXPECT_EQ(r.parameters_std_dev[1], 0.0);
  }
}

struct SharedCase {
  const char* set;
  const char* model;
  const char* guess;
};

AutoCalibratorSummary CalibrateShared(const fs::path& shared, const SharedCase& c,
                                      const fs::path& out, GroundTruth* truth) {
  const fs::path set = shared / "datasets" / "rendered" / c.set;
  *truth = ReadGroundTruth(set / "ground_truth.yaml");
  return Calibrate(set / "images", out, c.model, c.guess);
}

TEST(AutoCalibrationShared, DomePortDecenteringAndFocalLength) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  GroundTruth truth;
  const AutoCalibratorSummary result = CalibrateShared(
      *shared_opt, {"target3d_domeport", "DOMEPORT", "0,0,0,0.05,0.006,1,1.473,1.334"}, dir / "out",
      &truth);
  const CalibrationReport& r = result.refined.report;
  ASSERT_TRUE(r.housing);
  const Eigen::Vector3d c(r.housing->params[0], r.housing->params[1], r.housing->params[2]);
  const Eigen::Vector3d c_true(truth.housing->params[0], truth.housing->params[1],
                               truth.housing->params[2]);
  const double df = std::abs(r.camera.params[0] - truth.camera.params[0]);
  std::cout << "shared dome: |dC| " << (c - c_true).norm() * 1000 << " mm, dC "
            << (c - c_true).transpose() * 1000 << " mm, |df| " << df << " px\n";
  EXPECT_EQ(result.num_registered, 25);
  EXPECT_LT((c - c_true).norm(), 0.0005);  // the issue's goal (published tool: 5.2 mm)
  EXPECT_LT(df, 1.0);
}

TEST(AutoCalibrationShared, FlatPortNormalDistanceAndFocalLength) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  GroundTruth truth;
  const AutoCalibratorSummary result = CalibrateShared(
      *shared_opt, {"target3d_flatport", "FLATPORT", "0,0,1,0.02,0.014,1,1.473,1.334"}, dir / "out",
      &truth);
  const CalibrationReport& r = result.refined.report;
  ASSERT_TRUE(r.housing);
  const double angle = NormalAngle(r.housing->params, truth.housing->params);
  const double dd = std::abs(r.housing->params[3] - truth.housing->params[3]);
  const double df = std::abs(r.camera.params[0] - truth.camera.params[0]);
  std::cout << "shared flat: normal " << angle / kDegree << " deg, |dd| " << dd * 1000
            << " mm, |df| " << df << " px\n";
  EXPECT_EQ(result.num_registered, 25);
  // The issue's goals (the published tool: normal 0.02 deg, distance off by
  // 1.3 m without scale). Measured: 0.015 deg, 0.73 mm, 0.71 px.
  EXPECT_LT(dd, 0.001);
  EXPECT_LT(angle, 0.02 * kDegree);
  EXPECT_LT(df, 1.0);
}

}  // namespace
}  // namespace portcal
