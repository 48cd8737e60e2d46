// The portcal executable as a user runs it: help, exit codes, one-line
// errors naming the culprit, ini files, and the commands of the foundation.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/io/opencv_camera_file.h"
#include "colmap_ext/io/sparse_model.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::RunCommand;

std::string Portcal(const std::string& args) { return testing::PortcalBinary() + " " + args; }

TEST(Cli, HelpListsTheCommands) {
  const auto result = RunCommand(Portcal("help"));
  EXPECT_EQ(result.exit_code, 0);
  for (const char* command : {"database_creator", "model_converter", "project_points"}) {
    EXPECT_NE(result.output.find(command), std::string::npos) << command;
  }
  // Every name is followed by at least two spaces before its summary
  // (refractive_bundle_adjuster once ran into it).
  EXPECT_NE(result.output.find("  refractive_bundle_adjuster  "), std::string::npos)
      << result.output;
  EXPECT_EQ(RunCommand(Portcal("")).exit_code, 2);
  const auto unknown = RunCommand(Portcal("frobnicate"));
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("frobnicate"), std::string::npos);
}

TEST(Cli, CommandHelpShowsOptionsWithDefaults) {
  const auto result = RunCommand(Portcal("project_points -h"));
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.output.find("--Housing.model"), std::string::npos);
  EXPECT_NE(result.output.find("--log_level"), std::string::npos);
  EXPECT_NE(result.output.find("(=info)"), std::string::npos) << result.output;
  // Real defaults print as written, not as 0.80000000000000004.
  const auto matcher = RunCommand(Portcal("exhaustive_matcher -h"));
  EXPECT_NE(matcher.output.find("(=0.8)"), std::string::npos) << matcher.output;
  EXPECT_EQ(matcher.output.find("0000000"), std::string::npos) << matcher.output;
}

TEST(Cli, BadOptionsAreUsageErrorsNamingTheOption) {
  auto result = RunCommand(Portcal("model_converter --input_path a --output_path b --bogus 1"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("--bogus"), std::string::npos) << result.output;
  result = RunCommand(Portcal("model_converter --input_path a"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("output_path"), std::string::npos) << result.output;
  result = RunCommand(Portcal("database_creator --database_path x.db --log_level loud"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("log_level"), std::string::npos) << result.output;
}

TEST(Cli, ProjectPointsMatchesTheLibraryAndReportsInvalidPoints) {
  testing::TempDir dir;
  std::ofstream(dir / "points.txt") << "# X Y Z\n0.1 -0.05 1.2\n0 0 0.01\n0.3 0.2 2.5\n";
  const std::string camera =
      "--Camera.model RADIAL --Camera.params 1297.3655,960,540,-0.1,0.01 "
      "--Camera.width 1920 --Camera.height 1080";
  const std::string housing =
      "--Housing.model DOMEPORT --Housing.params '0.01 0.006 0.002 0.05 0.006 1 1.473 1.334'";
  const auto result =
      RunCommand(Portcal("project_points --log_level error --points_path " +
                         (dir / "points.txt").string() + " " + camera + " " + housing));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::istringstream lines(result.output);
  std::string first, second, third;
  std::getline(lines, first);
  std::getline(lines, second);
  std::getline(lines, third);
  Camera cam = Camera::FromModelName("RADIAL", 1297.3655, 1920, 1080);
  cam.params = {1297.3655, 960, 540, -0.1, 0.01};
  const Housing dome =
      Housing::FromName("DOMEPORT", {0.01, 0.006, 0.002, 0.05, 0.006, 1, 1.473, 1.334}, "test");
  const Eigen::Vector2d expected = *ProjectPoint(cam, &dome, Eigen::Vector3d(0.1, -0.05, 1.2));
  double x, y;
  std::istringstream(first) >> x >> y;
  EXPECT_EQ(x, expected.x());  // 17 digits: exact
  EXPECT_EQ(y, expected.y());
  EXPECT_EQ(second.rfind("invalid", 0), 0u) << second;  // inside the dome
  EXPECT_NE(third.rfind("invalid", 0), 0u) << third;

  // Unproject: the pixel's ray passes through the point.
  std::ofstream(dir / "pixels.txt") << first << "\n";
  const auto rays =
      RunCommand(Portcal("project_points --log_level error --unproject 1 "
                         "--points_path " +
                         (dir / "pixels.txt").string() + " " + camera + " " + housing));
  ASSERT_EQ(rays.exit_code, 0) << rays.output;
  Eigen::Vector3d origin, direction;
  std::istringstream(rays.output) >> origin.x() >> origin.y() >> origin.z() >> direction.x() >>
      direction.y() >> direction.z();
  const Eigen::Vector3d to_point = Eigen::Vector3d(0.1, -0.05, 1.2) - origin;
  EXPECT_LT((to_point - to_point.dot(direction) * direction).norm(), 1e-9);
}

TEST(Cli, ErrorsNameTheFileAndLine) {
  testing::TempDir dir;
  std::ofstream(dir / "bad.txt") << "0.1 0.2 1\n0.1 oops 1\n";
  const std::string camera =
      "--Camera.model PINHOLE --Camera.params 800,800,320,240 --Camera.width 640 "
      "--Camera.height 480";
  auto result = RunCommand(
      Portcal("project_points --points_path " + (dir / "bad.txt").string() + " " + camera));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("bad.txt:2"), std::string::npos) << result.output;
  result = RunCommand(
      Portcal("project_points --points_path " + (dir / "none.txt").string() + " " + camera));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("none.txt"), std::string::npos) << result.output;
  result = RunCommand(Portcal("project_points --points_path " + (dir / "bad.txt").string() +
                              " --Camera.model PINHOLE --Camera.params 800,800 "
                              "--Camera.width 640 --Camera.height 480"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("--Camera.params"), std::string::npos) << result.output;
  // The error is one line.
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

// The camera from a sparse model (its only one without --camera_id) or
// from a calibration file of another tool; without any camera, or with a
// model of several and no --camera_id, the error names the options.
TEST(Cli, ProjectPointsTakesTheCameraFromAModelOrACalibrationFile) {
  testing::TempDir dir;
  std::ofstream(dir / "points.txt") << "0 0 2\n";
  const std::string points =
      "project_points --log_level error --points_path " + (dir / "points.txt").string();
  Camera camera;
  camera.model_id = CameraModelNameToId("PINHOLE");
  camera.width = 640;
  camera.height = 480;
  camera.params = {800, 800, 320.5, 240.5};
  WriteRosCameraInfoYaml(camera, "test", dir / "ros.yaml");
  auto result = RunCommand(Portcal(points + " --input_calibration " + (dir / "ros.yaml").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "320.5 240.5\n");

  SparseModel model;
  camera.camera_id = 3;
  model.cameras[3] = camera;
  fs::create_directories(dir / "one");
  WriteSparseModel(model, dir / "one", ModelFormat::kText);
  result = RunCommand(Portcal(points + " --input_path " + (dir / "one").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "320.5 240.5\n");

  camera.camera_id = 4;
  model.cameras[4] = camera;
  fs::create_directories(dir / "two");
  WriteSparseModel(model, dir / "two", ModelFormat::kText);
  result = RunCommand(Portcal(points + " --input_path " + (dir / "two").string()));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("--camera_id"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("(3, 4)"), std::string::npos) << result.output;

  result = RunCommand(Portcal(points));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  for (const char* named : {"--input_path", "--input_calibration", "--Camera.model"}) {
    EXPECT_NE(result.output.find(named), std::string::npos) << named << ": " << result.output;
  }
}

TEST(Cli, ProjectPathReadsOptionsFromAnIniFile) {
  testing::TempDir dir;
  std::ofstream(dir / "points.txt") << "0 0 2\n";
  std::ofstream(dir / "project.ini")
      << "log_level = error\npoints_path = " << (dir / "points.txt").string() << "\n"
      << "[Camera]\nmodel = PINHOLE\nparams = 800,800,320.5,240.5\nwidth = 640\nheight = 480\n";
  const auto result =
      RunCommand(Portcal("project_points --project_path " + (dir / "project.ini").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "320.5 240.5\n");
}

TEST(Cli, DatabaseCreatorRefusesAFileThatIsNoDatabaseAndLeavesItAlone) {
  testing::TempDir dir;
  const std::string text(2000, 'x');
  std::ofstream(dir / "notes.db") << text;
  const auto result =
      RunCommand(Portcal("database_creator --database_path " + (dir / "notes.db").string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("notes.db"), std::string::npos) << result.output;
  EXPECT_EQ(testing::ReadFileToString(dir / "notes.db"), text);
  EXPECT_EQ(RunCommand(Portcal("database_creator --log_level error --database_path " +
                               (dir / "new.db").string()))
                .exit_code,
            0);
  EXPECT_TRUE(fs::exists(dir / "new.db"));
}

TEST(Cli, ModelConverterImportsTheForksCameras) {
  testing::TempDir dir;
  fs::create_directories(dir / "fork");
  std::ofstream(dir / "fork" / "cameras.txt")
      << "1 SIMPLE_RADIAL 1920 1080 1300 960 540 0.01 FLATPORT 0 0 1 0.02 0.014 1 1.473 1.334\n";
  std::ofstream(dir / "fork" / "images.txt") << "";
  std::ofstream(dir / "fork" / "points3D.txt") << "";
  auto result = RunCommand(Portcal("model_converter --log_level error --input_path " +
                                   (dir / "fork").string() + " --output_path " +
                                   (dir / "out").string() + " --output_type BIN"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const SparseModel model = ReadSparseModel(dir / "out");
  ASSERT_EQ(model.housings.count(1), 1u);
  EXPECT_EQ(model.housings.at(1).ModelName(), "FLATPORT");
  result = RunCommand(Portcal("model_converter --input_path " + (dir / "missing").string() +
                              " --output_path " + (dir / "out2").string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("missing"), std::string::npos);
  result = RunCommand(Portcal("model_converter --input_path " + (dir / "fork").string() +
                              " --output_path " + (dir / "out3").string() + " --output_type PLY"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("--output_type"), std::string::npos);
}

// One camera out to mrcal, OpenCV and ROS and back from mrcal, through the
// command line; a multi-camera model needs --camera_id.
TEST(Cli, ModelConverterExportsAndImportsOneCamera) {
  testing::TempDir dir;
  fs::create_directories(dir / "model");
  std::ofstream(dir / "model" / "cameras.txt")
      << "1 OPENCV 1440 1080 2412 2415 731.9 548.8 -0.36 0.16 0.0017 0.0016\n"
      << "2 PINHOLE 640 480 500 500 320 240\n";
  std::ofstream(dir / "model" / "images.txt") << "";
  std::ofstream(dir / "model" / "points3D.txt") << "";
  const std::string input = " --input_path " + (dir / "model").string();
  auto result =
      RunCommand(Portcal("model_converter" + input + " --output_type CAMERAMODEL --output_path " +
                         (dir / "c.cameramodel").string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("--camera_id"), std::string::npos) << result.output;
  for (const char* type : {"CAMERAMODEL", "OPENCV_YAML", "ROS_YAML"}) {
    const std::string out = (dir / (std::string("c_") + type)).string() +
                            (std::string(type) == "CAMERAMODEL" ? ".cameramodel" : ".yaml");
    result = RunCommand(Portcal("model_converter --log_level error" + input +
                                " --camera_id 1 --output_type " + type + " --output_path " + out));
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_TRUE(fs::exists(out)) << type;
  }
  result = RunCommand(Portcal("model_converter --log_level error --input_path " +
                              (dir / "c_CAMERAMODEL.cameramodel").string() +
                              " --output_type TXT --output_path " + (dir / "back").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const SparseModel back = ReadSparseModel(dir / "back");
  ASSERT_EQ(back.cameras.size(), 1u);
  EXPECT_EQ(back.cameras.at(1).ModelName(), "OPENCV");
  EXPECT_DOUBLE_EQ(back.cameras.at(1).params[2], 731.9);
}

// cross_check: usage errors exit 2; a missing calibration file exits 1 and
// names it.
TEST(Cli, CrossCheckNamesWhatIsMissing) {
  testing::TempDir dir;
  auto result = RunCommand(Portcal("cross_check --database_path " + (dir / "db.db").string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  result = RunCommand(Portcal("cross_check --database_path " + (dir / "db.db").string() +
                              " --input_calibration " + (dir / "nope.yaml").string() +
                              " --output_path " + (dir / "out").string()));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("nope.yaml"), std::string::npos) << result.output;
  result =
      RunCommand(Portcal("cross_check --database_path a --input_calibration b --output_path c "
                         "--CrossCheck.folds 1"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("--CrossCheck.folds"), std::string::npos) << result.output;
}

// The typed options (a housing, -1/0/1, a choice) are parsed in tools/ and
// their errors name the flag.
TEST(Cli, TypedOptionsNameTheFlagAtFault) {
  const std::string base = "auto_calibrator --image_path a --output_path b ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--Housing.params 0,0,1", "--Housing.params"},
      {"--Housing.model FLATPORT", "--Housing.params"},
      {"--Housing.model FLATPORT --Housing.params 0,0,1,0.01", "--Housing.params"},
      {"--Housing.model CYLINDER --Housing.params 0,0,1,0.01,0.01,1,1.5,1.33", "CYLINDER"},
      {"--AutoCalibration.refine_intrinsics 2", "--AutoCalibration.refine_intrinsics"},
      {"--AutoCalibration.matcher spatial", "--AutoCalibration.matcher"},
      {"--Housing.model DOMEPORT --Housing.params 0,0,0,43.552,3.75,1,1.495,1.333",
       "portcal takes metres"},
  };
  for (const auto& [flags, named] : cases) {
    const auto result = RunCommand(Portcal(base + flags));
    EXPECT_EQ(result.exit_code, 1) << flags << ": " << result.output;
    EXPECT_NE(result.output.find(named), std::string::npos) << flags << ": " << result.output;
  }
  // One help text for the housing flags, whichever command shows them.
  const std::string mapper = RunCommand(Portcal("refractive_mapper -h")).output;
  const std::string adjuster = RunCommand(Portcal("refractive_bundle_adjuster -h")).output;
  const auto params_help = [](const std::string& help) {
    const size_t at = help.find("--Housing.params");
    return at == std::string::npos ? std::string() : help.substr(at, help.find('\n', at) - at);
  };
  EXPECT_FALSE(params_help(mapper).empty()) << mapper;
  EXPECT_EQ(params_help(mapper), params_help(adjuster));
}

// A flag group that several commands expose (one Register per options
// struct in tools/option_groups.cc) reads the same in every command's help:
// same default, same text, whatever the column widths.
TEST(Cli, SharedFlagGroupsReadTheSameInEveryCommand) {
  const auto flag_help = [](const std::string& help, const std::string& flag) {
    // The option's own line (the command's summary may name it too).
    size_t at = help.find("\n  --" + flag + " ");
    if (at == std::string::npos) return std::string();
    ++at;
    const size_t end = help.find("\n  --", at);
    std::string text = help.substr(at, end == std::string::npos ? std::string::npos : end - at);
    std::string folded;
    for (const char c : text) {
      if (std::isspace(static_cast<unsigned char>(c))) {
        if (!folded.empty() && folded.back() != ' ') folded += ' ';
      } else {
        folded += c;
      }
    }
    return folded;
  };
  const std::vector<std::pair<std::string, std::vector<std::string>>> groups = {
      {"Markers.side_length",
       {"refractive_mapper", "refractive_bundle_adjuster", "auto_calibrator"}},
      {"Markers.side_sigma",
       {"refractive_mapper", "refractive_bundle_adjuster", "auto_calibrator"}},
      {"SiftExtraction.peak_threshold", {"feature_extractor", "auto_calibrator"}},
      {"ImageReader.single_camera_per_folder", {"feature_extractor", "target_extractor"}},
      {"SiftMatching.max_ratio", {"exhaustive_matcher", "sequential_matcher", "spatial_matcher"}},
      {"TwoViewGeometry.max_error",
       {"exhaustive_matcher", "sequential_matcher", "spatial_matcher"}},
      {"Markers.dictionary", {"feature_masker", "auto_calibrator"}},
      {"Mask.enlargement_factor", {"feature_masker", "auto_calibrator"}},
  };
  for (const auto& [flag, commands] : groups) {
    const std::string first = flag_help(RunCommand(Portcal(commands.front() + " -h")).output, flag);
    EXPECT_FALSE(first.empty()) << commands.front() << " shows no --" << flag;
    for (size_t k = 1; k < commands.size(); ++k) {
      EXPECT_EQ(flag_help(RunCommand(Portcal(commands[k] + " -h")).output, flag), first)
          << "--" << flag << " in " << commands[k] << " and " << commands.front();
    }
  }
  const auto result =
      RunCommand(Portcal("auto_calibrator --image_path a --output_path b --Markers.side_sigma 0"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("--Markers.side_sigma"), std::string::npos) << result.output;
}

// Boost guesses abbreviations by default: --Calibration.estimate would turn
// the board warp on. Here an abbreviated or unknown option is an error that
// names the options meant, and the database is not touched.
TEST(Cli, AbbreviatedOrUnknownOptionsAreRefusedWithSuggestions) {
  testing::TempDir dir;
  const std::string calibrate = "camera_calibrator --database_path " + (dir / "db.db").string() +
                                " --output_path " + (dir / "out").string();
  auto result = RunCommand(Portcal(calibrate + " --Calibration.estimate 1"));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("did you mean --Calibration.estimate_board_warp"), std::string::npos)
      << result.output;
  EXPECT_FALSE(fs::exists(dir / "db.db"));
  result = RunCommand(Portcal(calibrate + " --Calibration.estimate_bord_warp 1"));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--Calibration.estimate_board_warp"), std::string::npos)
      << result.output;
  // The same option under the group of another command.
  result = RunCommand(
      Portcal("feature_masker --database_path a --image_path b --Mask.dictionary DICT_4X4_50"));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("did you mean --Markers.dictionary"), std::string::npos)
      << result.output;
}

// "portcal help CMD" is "portcal CMD -h"; "-h GROUP" shows that group only.
TEST(Cli, HelpOfACommandAndOfOneGroup) {
  const auto full = RunCommand(Portcal("camera_calibrator -h"));
  ASSERT_EQ(full.exit_code, 0) << full.output;
  const auto via_help = RunCommand(Portcal("help camera_calibrator"));
  EXPECT_EQ(via_help.exit_code, 0) << via_help.output;
  EXPECT_EQ(via_help.output, full.output);
  const auto group = RunCommand(Portcal("camera_calibrator -h Calibration"));
  EXPECT_EQ(group.exit_code, 0) << group.output;
  EXPECT_NE(group.output.find("--Calibration.estimate_board_warp"), std::string::npos)
      << group.output;
  EXPECT_EQ(group.output.find("--database_path"), std::string::npos) << group.output;
  EXPECT_EQ(RunCommand(Portcal("help camera_calibrator Calibration")).output, group.output);
  const auto no_group = RunCommand(Portcal("camera_calibrator -h Nonsense"));
  EXPECT_EQ(no_group.exit_code, 2) << no_group.output;
  EXPECT_NE(no_group.output.find("Calibration"), std::string::npos) << no_group.output;
  EXPECT_EQ(RunCommand(Portcal("help no_such_command")).exit_code, 2);
}

TEST(Cli, PosePriorsNameWhatIsMissing) {
  testing::TempDir dir;
  const std::string db = (dir / "db.db").string();
  auto result =
      RunCommand(Portcal("pose_prior_importer --database_path " + db + " --input_path nav.txt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("--database_path"), std::string::npos) << result.output;
  ASSERT_EQ(
      RunCommand(Portcal("database_creator --log_level error --database_path " + db)).exit_code, 0);
  result = RunCommand(Portcal("pose_prior_importer --database_path " + db + " --input_path " +
                              (dir / "missing.txt").string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("missing.txt"), std::string::npos) << result.output;
  result = RunCommand(Portcal("spatial_matcher --database_path " + db));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("image"), std::string::npos) << result.output;
  result = RunCommand(Portcal(
      "refractive_bundle_adjuster --input_path a --output_path b --PosePrior.position_sigma 0.02"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("--database_path"), std::string::npos) << result.output;
}

// Work not done is an error naming its cause, and leaves nothing behind
// (issue 27's "success on nothing" and "messages that name nothing").
TEST(Cli, NothingDoneIsAnErrorNamingTheCause) {
  testing::TempDir dir;
  fs::create_directories(dir / "unreadable");
  std::ofstream(dir / "unreadable/a.png") << "not an image";
  auto result = RunCommand(Portcal("target_extractor --database_path " + (dir / "t.db").string() +
                                   " --image_path " + (dir / "unreadable").string() +
                                   " --Target.cols 8 --Target.rows 6 --Target.square_size 0.03"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("could be read"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir / "t.db"));  // the database it would have created

  std::ofstream(dir / "points.txt") << "0.1 0.2 1\n";
  // The answers to a full disk (stderr stays with the test).
  result = RunCommand(
      "(" +
      Portcal("project_points --points_path " + (dir / "points.txt").string() +
              " --Camera.model PINHOLE --Camera.params 800,800,320,240 --Camera.width 640 "
              "--Camera.height 480") +
      " > /dev/full)");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("standard output"), std::string::npos) << result.output;

  result = RunCommand(Portcal("stereo_calibrator --database_path " + (dir / "t.db").string() +
                              " --output_path " + (dir / "out").string() +
                              " --Stereo.camera1_id 1 --Stereo.camera2_id 1"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--Stereo.camera2_id"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir / "out"));

  std::ofstream(dir / "bogus.yaml")
      << "model: BOGUS_MODEL\nwidth: 10\nheight: 10\nparameters: [1]\n";
  result = RunCommand(Portcal("calibration_evaluator --database_path " + (dir / "t.db").string() +
                              " --input_calibration " + (dir / "bogus.yaml").string() +
                              " --output_path " + (dir / "eval").string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("bogus.yaml: model: unknown camera model 'BOGUS_MODEL'"),
            std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace portcal
