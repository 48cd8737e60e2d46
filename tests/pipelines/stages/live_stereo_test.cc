// live_calibrator with two sources, a stereo rig: a rendered rig trajectory
// played as two videos in real time keeps one pair per pause, in cam1/ and
// cam2/, each camera and the rig calibrated at the end; the result equals
// the batch stages on the kept frames and the truth within its standard
// deviations; frames pair by time, not by order.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/live/frame_pair_source.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/live_calibrator.h"
#include "pipelines/stages/stereo_calibrator.h"
#include "tests/pipelines/stages/live_test_setup.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// The batch stages on the kept frames: target_extractor (a camera per
// folder), camera_calibrator per camera, stereo_calibrator refining both.
StereoCalibrationResult BatchStereo(const testing::TempDir& dir) {
  const std::string batch_database = (dir / "batch.db").string();
  testing::ExtractBoard(dir / "kept", batch_database, true);
  Database database(batch_database, Database::OpenMode::kReadOnly);
  StereoCalibratorOptions stereo;
  for (const int camera : {1, 2}) {
    CameraCalibratorOptions calibrate;
    calibrate.database_path = batch_database;
    calibrate.camera_id =
        database.ReadImageWithName("cam" + std::to_string(camera) + "/live_0001.png")->camera_id;
    calibrate.output_path = (dir / ("batch_cam" + std::to_string(camera))).string();
    RunCameraCalibrator(calibrate, NoProgress());
    (camera == 1 ? stereo.camera1_id : stereo.camera2_id) = static_cast<int>(calibrate.camera_id);
    (camera == 1 ? stereo.input_calibration1 : stereo.input_calibration2) =
        (fs::path(calibrate.output_path) / "calibration.yaml").string();
  }
  stereo.database_path = batch_database;
  stereo.output_path = (dir / "batch_rig").string();
  stereo.stereo.refine_intrinsics = true;
  return RunStereoCalibrator(stereo, NoProgress());
}

TEST(LiveStereo, TwoVideosInRealTimeKeepOnePairPerPauseAndCalibrateTheRig) {
  const testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(dir, testing::LiveStereoTrajectoryYaml(11, 4, true));
  ASSERT_TRUE(truth.stereo.has_value());
  const std::vector<std::pair<int, int>> pauses =
      testing::TrajectoryPauses(dir / "set/trajectory.yaml");
  ASSERT_EQ(pauses.size(), 4u);
  LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "set/trajectory.avi").string());
  options.live.source2 = (dir / "set/trajectory_cam2.avi").string();
  const LiveCalibratorSummary summary = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(summary.session.end_reason, "the source ended");
  std::vector<int> kept_per_pause(pauses.size(), 0);
  for (const KeptView& kept : summary.session.kept_views) {
    const int frame = static_cast<int>(std::lround(kept.time_s * 10));
    for (size_t p = 0; p < pauses.size(); ++p) {
      if (frame >= pauses[p].first && frame <= pauses[p].second) ++kept_per_pause[p];
    }
    EXPECT_EQ(kept.view2.pixels.size(), 54u) << kept.name;
    EXPECT_TRUE(fs::exists(dir / "kept/cam1" / kept.name)) << kept.name;
    EXPECT_TRUE(fs::exists(dir / "kept/cam2" / kept.name)) << kept.name;
  }
  for (size_t p = 0; p < pauses.size(); ++p) EXPECT_EQ(kept_per_pause[p], 1) << "pause " << p;
  ASSERT_TRUE(summary.calibrated && summary.stereo && summary.camera && summary.camera2);
  EXPECT_TRUE(fs::exists(dir / "out/cam1/calibration.yaml"));
  EXPECT_TRUE(fs::exists(dir / "out/cam2/calibration.yaml"));
  EXPECT_TRUE(fs::exists(dir / "out/calibration.yaml"));
  {
    Database database(options.database_path, Database::OpenMode::kReadOnly);
    EXPECT_EQ(database.NumImages(), 8);
    EXPECT_EQ(database.NumCameras(), 2);
  }

  // Each camera's final calibration is its last live estimate, within 0.1σ.
  ASSERT_TRUE(summary.session.estimate && summary.session.estimate->camera2);
  const std::vector<std::pair<const LiveEstimate*, const CameraCalibrationResult*>> cameras = {
      {summary.session.estimate.get(), &*summary.camera},
      {summary.session.estimate->camera2.get(), &*summary.camera2}};
  for (const auto& [estimate, final_camera] : cameras) {
    ASSERT_TRUE(estimate->solved);
    ASSERT_EQ(estimate->values.size(), final_camera->camera.params.size());
    for (size_t k = 0; k < estimate->values.size(); ++k) {
      EXPECT_LE(std::abs(estimate->values[k] - final_camera->camera.params[k]),
                0.1 * final_camera->params_std_dev[k])
          << estimate->names[k];
    }
  }

  // The batch stages on the kept frames give the same rig.
  const StereoCalibrationResult batch = BatchStereo(dir);
  const StereoCalibrationResult& live = *summary.stereo;
  EXPECT_NEAR((live.cam2_from_cam1.translation - batch.cam2_from_cam1.translation).norm(), 0, 1e-9);
  EXPECT_NEAR(live.cam2_from_cam1.rotation.angularDistance(batch.cam2_from_cam1.rotation), 0, 1e-9);

  // And the truth, within its standard deviations (4 pairs, 0.1 m baseline).
  const Eigen::Vector3d error =
      live.cam2_from_cam1.translation - truth.stereo->cam2_from_cam1.translation;
  std::printf(
      "rig from %d pairs: translation error (%.4f, %.4f, %.4f) mm, sigma (%.4f, %.4f, %.4f) mm; "
      "rotation error %.4f deg\n",
      static_cast<int>(summary.session.kept), 1e3 * error.x(), 1e3 * error.y(), 1e3 * error.z(),
      1e3 * live.translation_std_dev.x(), 1e3 * live.translation_std_dev.y(),
      1e3 * live.translation_std_dev.z(),
      live.cam2_from_cam1.rotation.angularDistance(truth.stereo->cam2_from_cam1.rotation) * 180 /
          M_PI);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(live.translation_std_dev[k], 0);
    EXPECT_LT(std::abs(error[k]), 5 * live.translation_std_dev[k] + 1e-5)
        << "axis " << k << ": " << error[k] << " m, sigma " << live.translation_std_dev[k];
  }
}

// A rig behind two flat ports (each camera's own), the in-air intrinsics
// given, over two sessions: both ports within a few standard deviations of
// the truth, from a start on the axis 5 mm in front of the lens, and the
// rig's baseline.
TEST(LiveStereo, ARigBehindTwoFlatPortsIsCalibrated) {
  const testing::TempDir dir;
  std::string yaml = testing::LiveStereoTrajectoryYaml(11, 4, false);
  const std::string in_air = "housing: null";
  yaml.replace(yaml.find(in_air), in_air.size(),
               "housing: {model: FLATPORT, params: [0.0174524, 0, 0.9998477, 0.012, 0.008, 1.0, "
               "1.49, 1.334]}");
  yaml +=
      "  housing2: {model: FLATPORT, params: [-0.012198631, 0.008699023, 0.999887754, 0.015, "
      "0.008, 1.0, 1.49, "
      "1.334]}\n";
  const GroundTruth truth = testing::RenderSet(dir, yaml);
  ASSERT_TRUE(truth.stereo && truth.stereo->housing2);
  for (const int camera : {1, 2}) {
    CalibrationReport air;
    air.camera = camera == 1 ? truth.camera : truth.stereo->camera2;
    WriteCalibrationReport(air, dir / ("air" + std::to_string(camera)));
  }
  LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "set/images/cam1").string());
  options.live.source2 = (dir / "set/images/cam2").string();
  options.live.source.realtime = false;
  options.input_calibration = (dir / "air1/calibration.yaml").string();
  options.input_calibration2 = (dir / "air2/calibration.yaml").string();
  options.housing =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.005, 0.008, 1.0, 1.49, 1.334}, "test");
  // Two sessions: the second goes on from the first's two pairs (read back
  // by the name their images share), its frames joining the same cameras.
  options.live.max_views = 2;
  options.calibrate_at_end = false;
  EXPECT_EQ(RunLiveCalibrator(options, NoProgress()).session.kept, 2);
  options.live.max_views = 0;
  options.calibrate_at_end = true;
  const LiveCalibratorSummary summary = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(summary.session.kept, 4);
  {
    Database database(options.database_path, Database::OpenMode::kReadOnly);
    EXPECT_EQ(database.NumImages(), 8);
    EXPECT_EQ(database.NumCameras(), 2);
  }
  ASSERT_TRUE(summary.calibrated && summary.housing && summary.housing2 && summary.stereo);
  for (const auto& [result, port] : {std::pair{&*summary.housing, &*truth.housing},
                                     std::pair{&*summary.housing2, &*truth.stereo->housing2}}) {
    for (int k = 0; k < 4; ++k) {  // the normal and the distance
      const double sigma = result->housing_std_dev[k],
                   error = result->housing.params[k] - port->params[k];
      EXPECT_GT(sigma, 0) << k;
      EXPECT_LT(std::abs(error), 5 * sigma + 1e-6)
          << "parameter " << k << ": error " << error << ", sigma " << sigma;
    }
  }
  // The relative pose through the two ports, held: its own deviations leave
  // out the ports' (about a millimetre in their distances here).
  const Rigid3d& rig = summary.stereo->cam2_from_cam1;
  EXPECT_LT((rig.translation - truth.stereo->cam2_from_cam1.translation).norm(), 1e-3);
  EXPECT_LT(rig.rotation.angularDistance(truth.stereo->cam2_from_cam1.rotation) * 180 / M_PI, 0.1);
  EXPECT_TRUE(fs::exists(dir / "out/cam2/calibration.yaml"));
}

// Two folders at different rates: frames pair by their times (the second
// source's every frame with every other of the first), not by order.
TEST(FramePairSource, FramesPairByTimeNotByOrder) {
  const testing::TempDir dir;
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(128));
  fs::create_directories(dir / "fast");
  fs::create_directories(dir / "slow");
  for (int k = 0; k < 10; ++k)
    cv::imwrite((dir / ("fast/f" + std::to_string(k) + ".png")).string(), image);
  for (int k = 0; k < 5; ++k)
    cv::imwrite((dir / ("slow/s" + std::to_string(k) + ".png")).string(), image);
  FrameSourceOptions fast, slow;
  fast.source = (dir / "fast").string();
  fast.folder_fps = 10;
  fast.realtime = false;
  slow = fast;
  slow.source = (dir / "slow").string();
  slow.folder_fps = 5;
  FramePairSource pairs(fast, slow, 0.01);
  FramePair pair;
  std::vector<std::pair<int64_t, int64_t>> indices;
  while (pairs.Next(&pair) == FrameStatus::kFrame) {
    indices.emplace_back(pair.first.index, pair.second.index);
    EXPECT_LE(pair.offset_s, 0.01);
  }
  const std::vector<std::pair<int64_t, int64_t>> expected = {
      {0, 0}, {2, 1}, {4, 2}, {6, 3}, {8, 4}};
  EXPECT_EQ(indices, expected);
  EXPECT_EQ(pairs.dropped(), 4);  // 1, 3, 5, 7 of the fast one (9 is left when the slow one ends)
  // The default tolerance: half the slower source's frame interval.
  EXPECT_DOUBLE_EQ(FramePairSource(fast, slow, 0).tolerance_s(), 0.1);
}

TEST(LiveStereo, OptionsNameWhatIsWrong) {
  const testing::TempDir dir;
  LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "a").string());
  options.live.source2 = (dir / "a").string();
  try {
    options.Check();
    ADD_FAILURE() << "the same source twice accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--source2"), std::string::npos) << e.what();
  }
  options.live.source2 = "";
  options.input_calibration2 = "cam2.yaml";
  EXPECT_THROW(options.Check(), OptionError);
  // A missing second source: an error naming it, no database.
  options = testing::LiveOptions(dir, (dir / "no1.avi").string());
  fs::create_directories(dir / "frames");
  cv::imwrite((dir / "frames/a.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)));
  options.live.source.source = (dir / "frames").string();
  options.live.source2 = (dir / "no_such.avi").string();
  try {
    RunLiveCalibrator(options, NoProgress());
    ADD_FAILURE() << "a missing second source accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such.avi"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "live.db"));
}

}  // namespace
}  // namespace portcal
