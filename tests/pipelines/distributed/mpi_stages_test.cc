// The stages under `mpirun -np 2 --oversubscribe` (OpenMPI from Debian) on
// one machine: feature_extractor and the matchers leave the database with
// the very rows one process writes (compared table by table, the stage log
// aside), on a new database and on a COLMAP 4.1 one that already holds
// images; a rank that fails stops the job with nothing written and no
// shard left.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::RunCommand;

// mpirun refuses root unless told (CI's container runs as root).
std::string Mpirun() {
  return "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np 2 --oversubscribe ";
}

#define PORTCAL_REQUIRE_MPIRUN()                                                         \
  if (RunCommand("command -v mpirun").exit_code != 0) {                                  \
    GTEST_SKIP() << "mpirun is not installed (bash workflows/test.sh installs OpenMPI)"; \
  }

// Views of the two-face ArUco target in two folders (a/: 5, b/: 4).
fs::path RenderSet(const testing::TempDir& dir) {
  std::ofstream(dir / "set.yaml")
      << "name: mpi\nnum_images: 9\nseed: 3\n"
         "camera: {model: SIMPLE_RADIAL, width: 480, height: 270, params: [380.0, "
         "240.0, 135.0, -0.02]}\nhousing: null\n"
      << testing::kTwoFaceTargetYaml
      << "poses: {distance: [0.45, 0.9], tilt_max_deg: 35, roll_max_deg: 60, "
         "visibility: markers, border_margin_px: 10, max_view_angle_deg: 60}\n"
         "render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}\n";
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  RunSynthesize(synthesize, NoProgress());
  const fs::path images = dir / "images";
  fs::create_directories(images / "a");
  fs::create_directories(images / "b");
  int i = 0;
  for (const auto& entry : fs::directory_iterator(dir / "set" / "images")) {
    fs::copy_file(entry.path(), images / (i++ < 5 ? "a" : "b") / entry.path().filename());
  }
  return images;
}

// Every table's rows but the stage log's (times differ), schema included.
std::string Rows(const fs::path& database) {
  const testing::CommandResult tables =
      RunCommand("sqlite3 " + database.string() +
                 " \"SELECT name FROM sqlite_master WHERE type='table' AND name != "
                 "'portcal_stage_log' ORDER BY name;\"");
  std::string rows = RunCommand("sqlite3 " + database.string() + " .schema").output;
  std::istringstream names(tables.output);
  for (std::string table; std::getline(names, table);) {
    rows += table + ":\n" +
            RunCommand("sqlite3 " + database.string() + " \"SELECT * FROM " + table +
                       " ORDER BY 1, 2;\"")
                .output;
  }
  return rows;
}

void RunOrFail(const std::string& command) {
  const testing::CommandResult result = RunCommand(command + " --log_level warn 2>&1");
  ASSERT_EQ(result.exit_code, 0) << command << "\n" << result.output;
}

TEST(MpiStages, ExtractionAndMatchingOnTwoRanksWriteOneProcesssRows) {
  PORTCAL_REQUIRE_MPIRUN();
  const testing::TempDir dir;
  const fs::path images = RenderSet(dir);
  const std::string portcal = testing::PortcalBinary();
  for (const std::string& run : {std::string("one"), Mpirun()}) {
    const std::string prefix = run == "one" ? "" : run;
    const std::string db = (dir / (run == "one" ? "one.db" : "mpi.db")).string();
    RunOrFail(prefix + portcal + " feature_extractor --database_path " + db + " --image_path " +
              images.string() + " --ImageReader.single_camera_per_folder 1");
    RunOrFail(prefix + portcal + " exhaustive_matcher --database_path " + db);
  }
  const std::string one = Rows(dir / "one.db");
  EXPECT_NE(one.find("keypoints:\n1|"), std::string::npos) << one.substr(0, 2000);
  EXPECT_EQ(Rows(dir / "mpi.db"), one);
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().string().find(".shard-"), std::string::npos)
        << entry.path() << " left behind";
  }
}

TEST(MpiStages, ARerunOnAColmap41DatabaseAddsWhatOneProcessAdds) {
  PORTCAL_REQUIRE_MPIRUN();
  const testing::TempDir dir;
  const fs::path images = RenderSet(dir);
  const std::string portcal = testing::PortcalBinary();
  // Folder a/ first (one process, into both), then everything: b/'s images
  // join the shared camera, a/'s are skipped.
  fs::rename(images / "b", dir / "b");
  for (const char* name : {"one.db", "mpi.db"}) {
    const std::string db = (dir / name).string();
    RunOrFail(portcal + " database_creator --database_path " + db +
              " --Database.colmap_version 4.1");
    RunOrFail(portcal + " feature_extractor --database_path " + db + " --image_path " +
              images.string() + " --ImageReader.single_camera 1");
  }
  fs::rename(dir / "b", images / "b");
  for (const std::string& run : {std::string("one"), Mpirun()}) {
    const std::string prefix = run == "one" ? "" : run;
    const std::string db = (dir / (run == "one" ? "one.db" : "mpi.db")).string();
    RunOrFail(prefix + portcal + " feature_extractor --database_path " + db + " --image_path " +
              images.string() + " --ImageReader.single_camera 1");
    RunOrFail(prefix + portcal + " sequential_matcher --database_path " + db +
              " --SequentialMatching.overlap 3");
  }
  const std::string one = Rows(dir / "one.db");
  EXPECT_NE(one.find("frame_data:"), std::string::npos);
  EXPECT_EQ(Rows(dir / "mpi.db"), one);
  EXPECT_EQ(RunCommand("sqlite3 " + (dir / "mpi.db").string() + " 'SELECT count(*) FROM cameras;'")
                .output,
            "1\n");
}

TEST(MpiStages, ARankThatFailsLeavesNothing) {
  PORTCAL_REQUIRE_MPIRUN();
  const testing::TempDir dir;
  const fs::path images = RenderSet(dir);
  // The last image (rank 1's block) of another size than the camera all
  // share.
  const cv::Mat small(120, 160, CV_8UC1, cv::Scalar(128));
  cv::imwrite((images / "b" / "zz_small.png").string(), small);
  const std::string db = (dir / "mpi.db").string();
  const testing::CommandResult result =
      RunCommand(Mpirun() + testing::PortcalBinary() + " feature_extractor --database_path " + db +
                 " --image_path " + images.string() + " --ImageReader.single_camera 1 2>&1");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("zz_small.png"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("another rank of the MPI job failed"), std::string::npos)
      << result.output;
  EXPECT_FALSE(fs::exists(db));
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().string().find(".shard-"), std::string::npos)
        << entry.path() << " left behind";
  }
}

}  // namespace
}  // namespace portcal
