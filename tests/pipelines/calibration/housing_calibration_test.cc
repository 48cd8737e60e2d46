// Housing calibration on the shared renders, the in-air intrinsics given:
// at least as accurate as the published tool (dome |dC| 0.09 mm; flat normal
// 0.03 deg, distance 0.19 mm), up to 3 of portcal's standard deviations.
#include <gtest/gtest.h>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/stages/housing_calibrator.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::vector<CalibrationView> ExtractViews(const fs::path& images, const fs::path& database) {
  TargetExtractorOptions options;
  options.database_path = database.string();
  options.image_path = images.string();
  options.reader.camera_model = "RADIAL";
  options.reader.single_camera = true;
  NullProgress progress;
  RunTargetExtractor(options, progress);
  Database db(database, Database::OpenMode::kReadOnly);
  return ReadTargetViews(&db).by_camera.begin()->second;
}

TEST(HousingCalibration, DomeDecenteringFromTheSharedRender) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered/chess_domeport";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  Housing guess = *truth.housing;
  guess.params[0] = guess.params[1] = guess.params[2] = 0;  // centred: learn from the data
  const HousingCalibrationResult result =
      CalibrateHousing(ExtractViews(set / "images", dir / "db.db"), truth.camera, guess, {});
  const Eigen::Vector3d error(result.housing.params[0] - truth.housing->params[0],
                              result.housing.params[1] - truth.housing->params[1],
                              result.housing.params[2] - truth.housing->params[2]);
  const Eigen::Vector3d sigma(result.housing_std_dev[0], result.housing_std_dev[1],
                              result.housing_std_dev[2]);
  EXPECT_GT(sigma.minCoeff(), 0);
  EXPECT_LT(error.norm(), 0.09e-3 + 3 * sigma.norm());
  EXPECT_LT(result.overall_rms_px, 0.02);
}

TEST(HousingCalibration, FlatPortNormalAndDistanceFromTheSharedRender) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered/chess_flatport";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  Housing guess = *truth.housing;
  guess.params[0] = 0;
  guess.params[1] = 0;
  guess.params[2] = 1;
  guess.params[3] = 0.05;
  const HousingCalibrationResult result =
      CalibrateHousing(ExtractViews(set / "images", dir / "db.db"), truth.camera, guess, {});
  const Eigen::Vector3d normal(result.housing.params[0], result.housing.params[1], result.housing.params[2]);
  const Eigen::Vector3d true_normal(truth.housing->params[0], truth.housing->params[1],
                                    truth.housing->params[2]);
  const double angle_deg = std::acos(std::min(1.0, normal.normalized().dot(true_normal.normalized()))) * 180 / M_PI;
  // The normal's tangent-plane standard deviation, as an angle.
  const double sigma_deg = std::hypot(result.housing_std_dev[0], result.housing_std_dev[1]) * 180 / M_PI;
  EXPECT_GT(sigma_deg, 0);
  EXPECT_LT(angle_deg, 0.03 + 3 * sigma_deg);
  EXPECT_LT(std::abs(result.housing.params[3] - truth.housing->params[3]),
            0.19e-3 + 3 * result.housing_std_dev[3]);
  // The axis straight from the views' F matrices is already close.
  EXPECT_GT(std::abs(result.initial_axis.dot(true_normal.normalized())), std::cos(1.0 * M_PI / 180));
}

TEST(HousingCalibration, StageReadsTheInAirReportAndWritesTheHousing) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered/chess_domeport";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  ExtractViews(set / "images", dir / "db.db");
  CalibrationReport in_air;
  in_air.camera = truth.camera;
  WriteCalibrationReport(in_air, dir / "air");
  HousingCalibratorOptions options;
  options.database_path = (dir / "db.db").string();
  options.input_calibration = (dir / "air/calibration.yaml").string();
  options.output_path = (dir / "water").string();
  options.housing = HousingFromText("DOMEPORT", "0 0 0 0.05 0.006 1.0 1.473 1.334");
  RunHousingCalibrator(options, NoProgress());
  const CalibrationReport report = ReadCalibrationReport(dir / "water/calibration.yaml");
  ASSERT_TRUE(report.housing.has_value());
  EXPECT_EQ(report.housing->ModelName(), "DOMEPORT");
  EXPECT_NEAR(report.housing->params[0], 0.01, 1e-4);
  // --update_database: the housing and the intrinsics for the next stage.
  options.update_database = true;
  const HousingCalibrationResult result = RunHousingCalibrator(options, NoProgress());
  {
    Database database(dir / "db.db", Database::OpenMode::kReadOnly);
    const std::map<camera_t, Housing> housings = database.ReadAllHousings();
    ASSERT_EQ(housings.size(), 1u);
    EXPECT_EQ(housings.begin()->second.params, result.housing.params);
    EXPECT_EQ(database.ReadAllCameras().at(0).params, result.camera.params);
  }
  options.housing.reset();
  EXPECT_THROW(RunHousingCalibrator(options, NoProgress()), OptionError);
}

}  // namespace
}  // namespace portcal
