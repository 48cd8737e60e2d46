// hierarchical_mapper under `mpirun -np 2 --oversubscribe` on one machine:
// the small rendered survey of test_survey.h (48 images behind a flat port
// tilted 3 deg, navigation of 2 cm noise) cut into two
// overlapping clusters, each mapped on its own rank with the port refined
// and the navigation as the scale, merged and adjusted as a whole; then
// refined as refractive_mapper's model is. The merged model must give the
// sequential one's port and camera positions within the refinement's
// standard deviations. Surveys of 1000 images: workflows/bench_survey.sh.
// And, in one process, clusters that cannot be mapped.
#include "pipelines/stages/hierarchical_mapper.h"

#include <gtest/gtest.h>

#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/stages/refractive_bundle_adjuster.h"
#include "tests/pipelines/stages/test_survey.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr double kDegree = M_PI / 180.0;
constexpr char kGuess[] = "0,0,1,0.01,0.010,1,1.473,1.334";

// The mapper's options both paths share (survey_calibration_test's).
std::string MapperFlags() {
  return std::string(" --Housing.model FLATPORT --Housing.params ") + kGuess +
         " --Mapper.init_scene_depth 2.0 --Mapper.ba_refine_focal_length 0 "
         "--Mapper.ba_refine_extra_params 0"
         " --Mapper.ba_refine_housing 1 --PosePrior.position_sigma 0.02"
         " --Mapper.ba_calibration_settled_px 1.0 --Mapper.ba_calibration_settled_min_images 20";
}

CalibrationReport Refine(const fs::path& model, const fs::path& output,
                         const std::string& database) {
  RefractiveBundleAdjusterOptions refine;
  refine.input_path = model.string();
  refine.output_path = output.string();
  refine.database_path = database;
  refine.ba.position_prior_sigma_m = 0.02;
  return RunRefractiveBundleAdjuster(refine, NoProgress()).report;
}

double NormalAngle(const std::vector<double>& a, const std::vector<double>& b) {
  const Eigen::Vector3d na(a[0], a[1], a[2]), nb(b[0], b[1], b[2]);
  return std::acos(std::min(1.0, na.normalized().dot(nb.normalized())));
}

TEST(HierarchicalMapper, TwoClustersOnTwoRanksMergeIntoTheSequentialModel) {
  if (testing::RunCommand("command -v mpirun").exit_code != 0) {
    GTEST_SKIP() << "mpirun is not installed (bash workflows/test.sh installs OpenMPI)";
  }
  testing::TempDir dir;
  const std::string database = testing::RenderAndMatchTestSurvey(dir).database;
  const std::string portcal = testing::PortcalBinary();
  const testing::CommandResult sequential = testing::RunCommand(
      portcal + " refractive_mapper --log_level warn --database_path " + database +
      " --output_path " + (dir / "sequential").string() + MapperFlags());
  ASSERT_EQ(sequential.exit_code, 0) << sequential.output;
  // 24 images a cluster and 8 of overlap: two clusters of ~32.
  const testing::CommandResult hierarchical = testing::RunCommand(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np 2 --oversubscribe " +
      portcal + " hierarchical_mapper --log_level info --database_path " + database +
      " --output_path " + (dir / "hierarchical").string() + MapperFlags() +
      " --Hierarchical.leaf_max_num_images 24 --Hierarchical.image_overlap 8");
  ASSERT_EQ(hierarchical.exit_code, 0) << hierarchical.output;
  EXPECT_NE(hierarchical.output.find("2 clusters over 2 rank(s)"), std::string::npos)
      << hierarchical.output;
  EXPECT_NE(hierarchical.output.find("cluster 1 (rank 1)"), std::string::npos)
      << hierarchical.output;
  EXPECT_NE(hierarchical.output.find("merged cluster"), std::string::npos) << hierarchical.output;
  EXPECT_TRUE(fs::exists(dir / "hierarchical" / "clusters" / "1" / "0" / "images.bin"));

  const CalibrationReport a =
      Refine(dir / "sequential" / "0", dir / "sequential_refined", database);
  const CalibrationReport b =
      Refine(dir / "hierarchical" / "0", dir / "hierarchical_refined", database);
  ASSERT_GE(a.views.size(), 44u);
  EXPECT_GE(b.views.size(), a.views.size() - 2);
  // The port: the merged model's refinement within one standard deviation
  // of the sequential one's (each with sigma by its own covariance).
  const std::vector<double>& ha = a.housing->params;
  const std::vector<double>& hb = b.housing->params;
  const std::vector<double>& sd = a.housing_std_dev;
  const double angle = NormalAngle(ha, hb);
  std::cout << "port: normals " << angle / kDegree << " deg apart (sd "
            << std::hypot(sd[0], sd[1]) / kDegree << "), distances " << ha[3] * 1000 << " / "
            << hb[3] * 1000 << " mm (sd " << sd[3] * 1000 << ")\n";
  EXPECT_LT(angle, std::hypot(sd[0], sd[1]));
  EXPECT_LT(std::abs(ha[3] - hb[3]), sd[3]);
  // The camera centres, both in the navigation frame: apart by less than
  // the navigation's 2 cm noise over the square root of the images that
  // hold the frame (the frames' own uncertainty), times 3.
  std::map<std::string, Eigen::Vector3d> centres;
  for (const CalibratedView& view : a.views)
    centres[view.image_name] = view.cam_from_target.Inverse().translation;
  double worst = 0;
  for (const CalibratedView& view : b.views) {
    if (!centres.count(view.image_name)) continue;
    worst = std::max(
        worst, (view.cam_from_target.Inverse().translation - centres.at(view.image_name)).norm());
  }
  std::cout << "camera centres: at most " << worst * 1000 << " mm apart\n";
  EXPECT_LT(worst, 3 * 0.02 / std::sqrt(static_cast<double>(a.views.size())));
}

// Two strips of 10 images, not linked to each other, each image's 30
// verified matches with the next too few to start a model: two clusters.
// Each is tried and left out with a warning naming it, rather than the
// first failure ending the job; with none mapped the job fails, saying so,
// and leaves no output folder. One process: the clusters run in turn.
TEST(HierarchicalMapper, ClustersThatCannotBeMappedAreLeftOutEachNamed) {
  testing::TempDir dir;
  const std::string database = (dir / "db.db").string();
  {
    Database db(database, Database::OpenMode::kCreate);
    const camera_t camera = db.WriteCamera(Camera::FromModelName("SIMPLE_RADIAL", 700, 960, 540));
    FeatureKeypoints keypoints;
    for (int k = 0; k < 30; ++k)
      keypoints.push_back(FeatureKeypoint::FromScaleOrientation(100 + 20 * k, 270, 2, 0));
    FeatureMatches matches;
    for (point2D_t k = 0; k < 30; ++k) matches.push_back({k, k});
    TwoViewGeometry geometry;
    geometry.config = TwoViewGeometryConfig::kCalibrated;
    geometry.inlier_matches = matches;
    for (int i = 0; i < 20; ++i) {
      DatabaseImage image;
      image.name = std::to_string(i) + ".png";
      image.camera_id = camera;
      const image_t id = db.WriteImage(image);
      db.WriteKeypoints(id, keypoints);
      if (i % 10 == 0) continue;  // the first of a strip
      db.WriteMatches(id - 1, id, matches);
      db.WriteTwoViewGeometry(id - 1, id, geometry);
    }
  }
  const fs::path output = dir / "hierarchical";
  const testing::CommandResult run = testing::RunCommand(
      testing::PortcalBinary() + " hierarchical_mapper --log_level info --database_path " +
      database + " --output_path " + output.string() +
      " --Hierarchical.leaf_max_num_images 10 --Hierarchical.image_overlap 2");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("2 clusters"), std::string::npos) << run.output;
  for (const std::string cluster : {"cluster 0 (", "cluster 1 ("}) {
    const size_t at = run.output.find(cluster);
    ASSERT_NE(at, std::string::npos) << cluster << "\n" << run.output;
    EXPECT_NE(run.output.find("images) could not be mapped and is left out", at), std::string::npos)
        << run.output;
  }
  EXPECT_NE(run.output.find("no cluster of " + database + " could be mapped"), std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(output));
}

}  // namespace
}  // namespace portcal
