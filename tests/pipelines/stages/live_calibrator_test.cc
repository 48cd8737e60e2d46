// live_calibrator: a rendered hand-held trajectory played in real time as a
// video keeps one frame per pause and none while the target moves, and the
// result equals the batch stages on the same frames; bad sources, frames of
// another size and Ctrl-C lose nothing.
#include "pipelines/stages/live_calibrator.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/images/image_reader.h"
#include "pipelines/stages/camera_calibrator.h"
#include "tests/pipelines/stages/live_test_setup.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// Five pauses: 8.6 s of video.
const std::string kTrajectoryYaml = testing::LiveTrajectoryYaml(3, 5, true);

LiveCalibratorOptions Options(const testing::TempDir& dir, const std::string& source) {
  return testing::LiveOptions(dir, source);
}

// The final calibration is the last live estimate: every parameter within
// 0.1 of its standard deviation (the same views, the same model, the board
// fitted alike; only the start differs). Constants and held values equal.
void ExpectFinalIsTheLiveEstimate(const LiveSummary& session,
                                  const std::vector<double>& final_values,
                                  const std::vector<double>& final_std_devs) {
  ASSERT_TRUE(session.estimate && session.estimate->solved);
  const std::vector<double>& live = session.estimate->values;
  ASSERT_EQ(live.size(), final_values.size());
  ASSERT_EQ(final_std_devs.size(), final_values.size());
  for (size_t k = 0; k < live.size(); ++k) {
    EXPECT_LE(std::abs(live[k] - final_values[k]),
              0.1 * std::max(0.0, final_std_devs[k]) + 1e-9 * (1 + std::abs(final_values[k])))
        << session.estimate->names[k] << ": live " << live[k] << ", final " << final_values[k]
        << " +- " << final_std_devs[k];
  }
}

CameraCalibrationResult Calibrate(const std::string& database, const fs::path& output) {
  CameraCalibratorOptions options;
  options.database_path = database;
  options.output_path = output.string();
  return RunCameraCalibrator(options, NoProgress());
}

TEST(LiveCalibrator, HandsFreeKeepsOneFramePerPauseAndMatchesTheBatchStages) {
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  const std::vector<std::pair<int, int>> pauses =
      testing::TrajectoryPauses(dir / "set/trajectory.yaml");
  ASSERT_EQ(pauses.size(), 5u);
  // In real time, as a camera would deliver it: frames the session is late
  // for are dropped.
  const LiveCalibratorSummary summary =
      RunLiveCalibrator(Options(dir, (dir / "set/trajectory.avi").string()), NoProgress());
  EXPECT_EQ(summary.session.end_reason, "the source ended");
  EXPECT_TRUE(summary.calibrated);
  std::vector<int> kept_per_pause(pauses.size(), 0);
  for (const KeptView& kept : summary.session.kept_views) {
    const int frame = static_cast<int>(std::lround(kept.time_s * 10));
    int pause = -1;
    for (size_t p = 0; p < pauses.size(); ++p) {
      if (frame >= pauses[p].first && frame <= pauses[p].second) pause = static_cast<int>(p);
    }
    EXPECT_GE(pause, 0) << kept.name << " is frame " << frame << ", taken while the target moved";
    if (pause >= 0) ++kept_per_pause[static_cast<size_t>(pause)];
  }
  for (size_t p = 0; p < pauses.size(); ++p) EXPECT_EQ(kept_per_pause[p], 1) << "pause " << p;
  ASSERT_TRUE(summary.camera);
  ExpectFinalIsTheLiveEstimate(summary.session, summary.camera->camera.params,
                               summary.camera->params_std_dev);

  // The batch stages on the kept frames: the same corners, the same camera.
  testing::ExtractBoard(dir / "kept", dir / "batch.db", false);
  const CameraCalibrationResult live = Calibrate((dir / "live.db").string(), dir / "out_live");
  const CameraCalibrationResult batch = Calibrate((dir / "batch.db").string(), dir / "out_batch");
  ASSERT_EQ(live.camera.params.size(), batch.camera.params.size());
  for (size_t k = 0; k < live.camera.params.size(); ++k) {
    EXPECT_NEAR(live.camera.params[k], batch.camera.params[k],
                1e-9 * (1 + std::abs(batch.camera.params[k])));
  }
  EXPECT_EQ(live.num_points, batch.num_points);
  EXPECT_TRUE(fs::exists(dir / "out/calibration.yaml"));
}

// Behind a flat port: the in-air intrinsics given, the port calibrated by
// housing_calibrator at the end, within a few standard deviations of the
// truth (and far from the start, 7 mm and 1 deg off).
TEST(LiveCalibrator, AHousingIsCalibratedFromTheKeptViews) {
  const testing::TempDir dir;
  std::string yaml = testing::LiveTrajectoryYaml(6, 5, false);
  const std::string in_air = "housing: null";
  yaml.replace(yaml.find(in_air), in_air.size(),
               "housing: {model: FLATPORT, params: [0.0174524, 0, 0.9998477, 0.012, 0.008, 1.0, "
               "1.49, 1.334]}");
  testing::RenderSet(dir, yaml);
  CalibrationReport air;
  air.camera = Camera::FromModelName("OPENCV", 505, 640, 480);
  air.camera.params = {505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007};
  WriteCalibrationReport(air, dir / "air");
  LiveCalibratorOptions options = Options(dir, (dir / "set/images").string());
  options.live.source.realtime = false;
  options.input_calibration = (dir / "air/calibration.yaml").string();
  options.housing =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.005, 0.008, 1.0, 1.49, 1.334}, "test");
  const LiveCalibratorSummary summary = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(summary.session.kept, 5);
  ASSERT_TRUE(summary.calibrated && summary.housing);
  EXPECT_TRUE(fs::exists(dir / "out/calibration.yaml"));
  const std::vector<double>& p = summary.housing->housing.params;
  const std::vector<double>& sigma = summary.housing->housing_std_dev;
  ExpectFinalIsTheLiveEstimate(summary.session, p, sigma);
  ASSERT_EQ(sigma.size(), p.size());
  const std::vector<double> truth = {0.0174524, 0, 0.9998477, 0.012};
  for (int k = 0; k < 4; ++k) {
    EXPECT_GT(sigma[k], 0) << k;
    EXPECT_LT(std::abs(p[k] - truth[k]), 5 * sigma[k] + 1e-6)
        << "parameter " << k << ": " << p[k] << " ± " << sigma[k];
  }
}

// A second session on the same database goes on from the first: the views
// already kept are not kept again, the new ones join the same camera.
TEST(LiveCalibrator, ASecondSessionGoesOnFromTheFirst) {
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  LiveCalibratorOptions options = Options(dir, (dir / "set/images").string());
  options.live.source.realtime = false;
  options.live.max_views = 2;
  options.calibrate_at_end = false;
  EXPECT_EQ(RunLiveCalibrator(options, NoProgress()).session.kept, 2);
  options.live.max_views = 0;
  options.calibrate_at_end = true;
  const LiveCalibratorSummary second = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(second.session.kept, 5);  // the two, then the three later pauses
  ASSERT_TRUE(second.camera.has_value());
  EXPECT_EQ(second.camera->views.size(), 5u);
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  EXPECT_EQ(database.NumImages(), 5);
  EXPECT_EQ(database.NumCameras(), 1);
}

// Two sessions at once on one database: the second is refused at start with
// a clear message (they would write images of the same names and stall on
// each other's transactions); the first goes on.
TEST(LiveCalibrator, ASecondSessionOnTheSameDatabaseAtOnceIsRefused) {
  const testing::TempDir dir;
  testing::RenderSet(dir, kTrajectoryYaml);
  LiveCalibratorOptions options = Options(dir, (dir / "set/images").string());
  options.live.source.realtime = false;
  options.calibrate_at_end = false;
  std::string refusal;
  const LiveCalibratorSummary first =
      RunLiveCalibrator(options, NoProgress(), [&](LiveSession& session, const std::string&) {
        LiveCalibratorOptions second = options;
        second.image_path = (dir / "kept2").string();
        second.output_path = (dir / "out2").string();
        try {
          RunLiveCalibrator(second, NoProgress());
        } catch (const DatabaseError& e) {
          refusal = e.what();
        }
        session.Finish();
      });
  EXPECT_NE(refusal.find("another live_calibrator session is using this database"),
            std::string::npos)
      << refusal;
  EXPECT_EQ(first.session.end_reason, "finish requested");
  EXPECT_FALSE(fs::exists(dir / "kept2"));
}

TEST(LiveCalibrator, AMissingDeviceOrFileIsAClearError) {
  const testing::TempDir dir;
  for (const std::string& source :
       std::vector<std::string>{"/dev/video97", (dir / "no_such.avi").string()}) {
    try {
      RunLiveCalibrator(Options(dir, source), NoProgress());
      ADD_FAILURE() << source << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(source), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(dir / "live.db")) << "a database made for nothing";
}

// A folder: the frames of a short trajectory, one of another size among
// them. Not in real time: every frame is processed.
int FolderWithAnOddFrame(const testing::TempDir& dir) {
  testing::RenderSet(dir, kTrajectoryYaml);
  const std::vector<std::string> names = ListImages(dir / "set/images");

  cv::Mat odd;
  cv::resize(cv::imread((dir / "set/images" / names[30]).string()), odd, cv::Size(320, 240));
  cv::imwrite((dir / "set/images" / names[30]).string(), odd);
  return static_cast<int>(names.size());
}

TEST(LiveCalibrator, FramesOfAnotherSizeAreSkippedAndCtrlCKeepsTheViews) {
  const testing::TempDir dir;
  const int num_frames = FolderWithAnOddFrame(dir);
  LiveCalibratorOptions options = Options(dir, (dir / "set/images").string());
  options.live.source.realtime = false;
  // Ctrl-C once three views are kept.
  std::thread watcher;
  const auto on_start = [&](LiveSession& session, const std::string&) {
    watcher = std::thread([&session] {
      while (session.Snapshot().kept.size() < 3)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      CancelFlag::Request();
    });
  };
  EXPECT_THROW(RunLiveCalibrator(options, NoProgress(), on_start), Cancelled);
  watcher.join();
  CancelFlag::Reset();
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  EXPECT_EQ(database.NumImages(), 3);
  for (const DatabaseImage& image : database.ReadAllImages()) {
    EXPECT_TRUE(fs::exists(dir / "kept" / image.name)) << image.name;
    EXPECT_EQ(database.ReadTargetObservations(image.image_id).size(), 54u) << image.name;
  }

  // The whole folder: the odd frame is skipped with a warning, the rest go on.
  options.database_path = (dir / "all.db").string();
  options.image_path = (dir / "kept_all").string();
  const LiveCalibratorSummary summary = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(summary.session.frames, num_frames - 1);
  EXPECT_EQ(summary.session.kept, 5);

  // A stream whose size changes for good (the last pause's frames): an
  // error naming the sizes, and the views kept before it stay.
  const std::vector<std::string> names = ListImages(dir / "set/images");
  for (size_t k = names.size() - 12; k < names.size(); ++k) {
    cv::Mat odd;
    cv::resize(cv::imread((dir / "set/images" / names[k]).string()), odd, cv::Size(320, 240));
    cv::imwrite((dir / "set/images" / names[k]).string(), odd);
  }
  options.database_path = (dir / "changed.db").string();
  options.image_path = (dir / "kept_changed").string();
  options.live.source.stall_seconds = 1e-3;
  try {
    RunLiveCalibrator(options, NoProgress());
    ADD_FAILURE() << "frames of another size for good were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("changed size to 320x240 instead of 640x480"),
              std::string::npos)
        << e.what();
  }
  Database changed(options.database_path, Database::OpenMode::kReadOnly);
  EXPECT_EQ(changed.NumImages(), 4);  // the four pauses before
}

}  // namespace
}  // namespace portcal
