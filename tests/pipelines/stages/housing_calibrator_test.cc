// housing_calibrator with the camera's in-air views at hand in the two
// forms a user keeps them: the database (--in_air_database_path) and
// camera_calibrator's camera.cameramodel, whose optimization_inputs carry
// the same views -- also after mrcal's Python re-serialised them (NumPy's
// own .npz). Each is the same joint solve: the housing and the lens agree
// to a thousandth of their standard deviations.
#include "pipelines/stages/housing_calibrator.h"

#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/housing/housing_models.h"
#include "pipelines/stages/camera_calibrator.h"
#include "tests/database/colmap_fixture.h"
#include "tests/pipelines/stages/live_test_setup.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

fs::path BoardSet(const std::string& name, const std::string& housing) {
  return testing::SharedRenderedImages(
      "name: " + name + "\nseed: 11\nnum_images: 6\n" +
      "camera: {model: OPENCV, width: 480, height: 360, params: [400.0, 402.0, 243.0, 178.0, "
      "-0.06, 0.01, 0.0, 0.0]}\n" +
      housing +
      "target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}\n" +
      "poses: {distance: [0.3, 0.6], tilt_max_deg: 40, roll_max_deg: 30}\nrender: {spp: 2, "
      "noise_sigma: 1.0}\n");
}

HousingCalibrationResult Calibrate(const fs::path& dome_db, const std::string& in_air_db,
                                   const std::string& input_calibration, const fs::path& output) {
  HousingCalibratorOptions housing;
  housing.database_path = dome_db.string();
  housing.in_air_database_path = in_air_db;
  housing.input_calibration = input_calibration;
  housing.output_path = output.string();
  housing.housing =
      Housing::FromName("DOMEPORT", {0, 0, 0, 0.05, 0.006, 1.0, 1.473, 1.334}, "test");
  return RunHousingCalibrator(housing, NoProgress());
}

void ExpectSameSolve(const HousingCalibrationResult& result,
                     const HousingCalibrationResult& reference, const std::string& what) {
  for (int i = 0; i < 3; ++i) {
    ASSERT_GT(reference.housing_std_dev[i], 0) << what;
    EXPECT_NEAR(result.housing.params[i], reference.housing.params[i],
                1e-3 * reference.housing_std_dev[i])
        << what << ": dome centre " << i;
    EXPECT_NEAR(result.housing_std_dev[i], reference.housing_std_dev[i],
                1e-3 * reference.housing_std_dev[i])
        << what;
  }
  for (size_t i = 0; i < reference.camera.params.size(); ++i) {
    EXPECT_NEAR(result.camera.params[i], reference.camera.params[i],
                1e-3 * reference.camera_std_dev[i])
        << what << ": intrinsic " << i;
  }
}

TEST(HousingCalibrator, CameraModelsInAirViewsGiveTheJointSolve) {
  testing::TempDir dir;
  testing::ExtractBoard(BoardSet("air", "housing: null\n"), dir / "air.db", false, "OPENCV", 8,
                        0.025);
  testing::ExtractBoard(BoardSet("dome",
                                 "housing: {model: DOMEPORT, params: [0.003, -0.002, 0.005, 0.05, "
                                 "0.006, 1.0, 1.473, 1.334]}\n"),
                        dir / "dome.db", false, "OPENCV", 8, 0.025);
  CameraCalibratorOptions camera;
  camera.database_path = (dir / "air.db").string();
  camera.output_path = (dir / "air").string();
  RunCameraCalibrator(camera, NoProgress());
  const fs::path model = dir / "air/camera.cameramodel";
  ASSERT_TRUE(fs::exists(model));

  const HousingCalibrationResult joint =
      Calibrate(dir / "dome.db", (dir / "air.db").string(), "", dir / "joint");
  const HousingCalibrationResult from_model =
      Calibrate(dir / "dome.db", "", model.string(), dir / "model");
  EXPECT_GT(from_model.camera_covariance.size(), 0) << "the lens was held, not solved jointly";
  ExpectSameSolve(from_model, joint, "camera_calibrator's .cameramodel");
  EXPECT_NE(testing::ReadFileToString(dir / "model/calibration.txt")
                .find("joint solve with 6 in-air views"),
            std::string::npos);

  if (testing::RunCommand("/usr/bin/python3 -c 'import mrcal' 2>&1").exit_code != 0) {
    GTEST_SKIP() << "mrcal is not importable by /usr/bin/python3: its re-serialisation not tried";
  }
  const fs::path rewritten = dir / "mrcal.cameramodel";
  const auto run = testing::RunCommand(
      "/usr/bin/python3 -c \"import mrcal; m = mrcal.cameramodel('" + model.string() +
      "'); mrcal.cameramodel(optimization_inputs=m.optimization_inputs(), "
      "icam_intrinsics=0).write('" +
      rewritten.string() + "')\" 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_NE(testing::ReadFileToString(rewritten), testing::ReadFileToString(model));
  ExpectSameSolve(Calibrate(dir / "dome.db", "", rewritten.string(), dir / "mrcal"), joint,
                  "mrcal's re-serialised .cameramodel");
}

}  // namespace
}  // namespace portcal
