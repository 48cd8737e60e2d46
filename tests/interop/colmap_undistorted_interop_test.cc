// image_undistorter's output against the real `colmap` 3.8 binary: the
// workspace's model reads in model_analyzer and model_converter, and
// colmap's mapper, with the virtual pinhole held fixed, reconstructs
// undistorted rendered views taken behind a flat port with the cameras
// where the renderer put them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/calibration_report.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

using testing::RunCommand;

// A lawnmower survey 2 m over a rough seabed (+-0.15 m relief), behind a
// port tilted 3 deg, lens with barrel distortion and an off-centre
// principal point; 24 images of 640 x 360.
const char* const kSurveyYaml = R"(name: undistorted_survey
seed: 28
num_images: 24
camera: {model: RADIAL, width: 640, height: 360, params: [466.7, 322.5, 177.0, -0.03, 0.0]}
housing: {model: FLATPORT, params: [0.0523360, 0.0, 0.9986295, 0.02, 0.010, 1.0, 1.473, 1.334]}
survey: {height: 2.0, speed: 0.5, frame_rate: 1.0, side_overlap: 0.6, line_length: 4.0,
         roughness: 0.15, relief_wavelength: 2.0, navigation_sigma: 0.02}
render: {spp: 2, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)";

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

TEST(ColmapUndistortedInterop, WorkspaceModelReadsInColmap) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(dir, kSurveyYaml);
  // A stock COLMAP-style model of two rendered views (ground-truth poses,
  // no points) plus housings.txt.
  SparseModel model;
  model.cameras[1] = truth.camera;
  model.cameras[1].camera_id = 1;
  model.housings[1] = *truth.housing;
  for (image_t id : {1u, 2u}) {
    Image& image = model.images[id];
    image.image_id = id;
    image.name = fs::path(truth.images[id - 1].cam1.file).filename().string();
    image.camera_id = 1;
    image.cam_from_world = truth.images[id - 1].cam1.cam_from_target;
  }
  WriteSparseModel(model, dir / "model", ModelFormat::kBinary);
  const testing::CommandResult undistort =
      RunCommand(testing::PortcalBinary() + " image_undistorter --input_path " +
                 Quoted(dir / "model") + " --image_path " + Quoted(dir / "set" / "images") +
                 " --output_path " + Quoted(dir / "out") + " --Undistort.distance 2");
  ASSERT_EQ(undistort.exit_code, 0) << undistort.output;
  const testing::CommandResult analyzed =
      RunCommand(colmap + " model_analyzer --path " + Quoted(dir / "out" / "sparse"));
  ASSERT_EQ(analyzed.exit_code, 0) << analyzed.output;
  EXPECT_NE(analyzed.output.find("Registered images: 2"), std::string::npos) << analyzed.output;
  fs::create_directories(dir / "txt");
  const testing::CommandResult converted =
      RunCommand(colmap + " model_converter --input_path " + Quoted(dir / "out" / "sparse") +
                 " --output_path " + Quoted(dir / "txt") + " --output_type TXT");
  ASSERT_EQ(converted.exit_code, 0) << converted.output;
  EXPECT_NE(testing::ReadFileToString(dir / "txt" / "cameras.txt").find("1 PINHOLE "),
            std::string::npos);
}

// Camera centres of `estimate` aligned to the truth's by a similarity
// (Umeyama); the RMS distance in metres.
double AlignedCentreRms(const SparseModel& estimate, const GroundTruth& truth, int* num_matched) {
  std::vector<Eigen::Vector3d> ours, theirs;
  for (const FrameTruth& frame : truth.images) {
    const std::string name = fs::path(frame.cam1.file).filename().string();
    for (const auto& [id, image] : estimate.images) {
      if (image.name != name) continue;
      ours.push_back(image.cam_from_world.Inverse().translation);
      theirs.push_back(frame.cam1.cam_from_target.Inverse().translation);
    }
  }
  *num_matched = static_cast<int>(ours.size());
  Eigen::Matrix3Xd a(3, ours.size()), b(3, theirs.size());
  for (size_t i = 0; i < ours.size(); ++i)
    a.col(static_cast<Eigen::Index>(i)) = ours[i], b.col(static_cast<Eigen::Index>(i)) = theirs[i];
  const Eigen::Matrix4d transform = Eigen::umeyama(a, b, true);
  const Eigen::Matrix3Xd aligned =
      (transform.topLeftCorner<3, 3>() * a).colwise() + transform.topRightCorner<3, 1>();
  return std::sqrt((aligned - b).colwise().squaredNorm().mean());
}

// The positions' tolerance: the pinhole's worst error over the seabed's
// depths (1.85-2.15 m) is ~0.2 px, which at 2 m and f = 623 px moves a
// view's solution by ~0.6 mm; over 24 chained views, 1 cm RMS (0.25 % of
// the 4 m path). Measured: 1.4-2.6 mm (colmap is not deterministic on two
// threads). The same views with the lens's in-air
// focal length held instead of the pinhole's miss by far more (see
// docs/benchmarks.md).
TEST(ColmapUndistortedInterop, ColmapMapperRecoversTheSurveyAtTheDesignDistance) {
  PORTCAL_REQUIRE_COLMAP(colmap);
  testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(dir, kSurveyYaml);
  CalibrationReport calibration;
  calibration.camera = truth.camera;
  calibration.housing = truth.housing;
  WriteCalibrationReport(calibration, dir / "cal");
  const testing::CommandResult undistort = RunCommand(
      testing::PortcalBinary() + " image_undistorter --input_path " +
      Quoted(dir / "cal" / "calibration.yaml") + " --image_path " + Quoted(dir / "set" / "images") +
      " --output_path " + Quoted(dir / "out") + " --Undistort.distance 2");
  ASSERT_EQ(undistort.exit_code, 0) << undistort.output;
  const Camera pinhole = ReadSparseModel(dir / "out" / "sparse").cameras.at(1);
  std::string params;
  for (const double p : pinhole.params) params += (params.empty() ? "" : ",") + FormatShortest(p);
  const std::string database = Quoted(dir / "colmap.db");
  const std::string images = Quoted(dir / "out" / "images");
  fs::create_directories(dir / "colmap");
  for (const std::string& command :
       {colmap + " feature_extractor --database_path " + database + " --image_path " + images +
            " --ImageReader.camera_model PINHOLE --ImageReader.single_camera 1 "
            "--ImageReader.camera_params " +
            params + " --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2",
        colmap + " exhaustive_matcher --database_path " + database +
            " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2",
        colmap + " mapper --database_path " + database + " --image_path " + images +
            " --output_path " + Quoted(dir / "colmap") +
            " --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_principal_point 0" +
            " --Mapper.ba_refine_extra_params 0 --Mapper.num_threads 2"}) {
    const testing::CommandResult result = RunCommand(command);
    ASSERT_EQ(result.exit_code, 0) << command << "\n" << result.output;
  }
  const SparseModel reconstruction = ReadSparseModel(dir / "colmap" / "0");
  int num_matched = 0;
  const double rms = AlignedCentreRms(reconstruction, truth, &num_matched);
  std::printf(
      "colmap mapper on the undistorted survey: %d of 24 images, camera centres %.2f mm RMS from "
      "the truth\n",
      num_matched, 1000 * rms);
  EXPECT_EQ(num_matched, 24);
  EXPECT_LT(rms, 0.01);
}

}  // namespace
}  // namespace portcal
