// Position priors: stored as COLMAP 3.8 stores GPS positions, imported from
// a navigation file in one transaction, and, in the bundle adjustment, the
// metric scale that lets a survey without markers self-calibrate a flat
// port's distance. The same synthetic survey also serves the bounded
// adjustment's solver (no line search) and an adjustment's start with an
// observation that cannot be projected.
#include "pipelines/bundle_adjustment/position_priors.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>
#include <iostream>
#include <random>
#include <set>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/progress.h"
#include "database/database.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/stages/feature_matcher.h"
#include "pipelines/stages/pose_prior_importer.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// prior_q* and prior_t* of an image, as SQL text ("NULL" for NULL).
std::string RawPriorColumns(const fs::path& path, const std::string& name) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  const std::string sql =
      "SELECT prior_qw, prior_qx, prior_qy, prior_qz, prior_tx, prior_ty, prior_tz "
      "FROM images WHERE name='" +
      name + "';";
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK);
  std::string out;
  if (sqlite3_step(stmt) == SQLITE_ROW) {
    for (int i = 0; i < 7; ++i) {
      out += sqlite3_column_type(stmt, i) == SQLITE_NULL
                 ? "NULL"
                 : std::to_string(sqlite3_column_double(stmt, i));
      out += i < 6 ? " " : "";
    }
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return out;
}

// A database with images a.png, b.png, c.png.
fs::path ThreeImageDatabase(const testing::TempDir& dir) {
  const fs::path path = dir / "db.db";
  Database database(path, Database::OpenMode::kCreate);
  Camera camera = Camera::FromModelName("PINHOLE", 700, 960, 540);
  camera.camera_id = database.WriteCamera(camera);
  for (const char* name : {"a.png", "b.png", "c.png"}) {
    DatabaseImage image;
    image.name = name;
    image.camera_id = camera.camera_id;
    database.WriteImage(image);
  }
  return path;
}

TEST(PositionPrior, StoredAsColmapStoresGpsPositions) {
  testing::TempDir dir;
  const fs::path path = ThreeImageDatabase(dir);
  {
    Database database(path, Database::OpenMode::kReadWrite);
    database.UpdatePositionPrior(database.ReadImageWithName("b.png")->image_id,
                                 Eigen::Vector3d(1.5, -2, 3.25));
    EXPECT_THROW(database.UpdatePositionPrior(99, Eigen::Vector3d::Zero()), InputError);
  }
  // prior_q NULL, prior_t the position (COLMAP 3.8's EXIF GPS import).
  EXPECT_EQ(RawPriorColumns(path, "b.png"), "NULL NULL NULL NULL 1.500000 -2.000000 3.250000");
  EXPECT_EQ(RawPriorColumns(path, "a.png"), "NULL NULL NULL NULL NULL NULL NULL");
  Database database(path, Database::OpenMode::kReadOnly);
  const DatabaseImage b = *database.ReadImageWithName("b.png");
  EXPECT_FALSE(b.cam_from_world_prior.has_value());
  ASSERT_TRUE(b.PriorPosition().has_value());
  EXPECT_EQ(*b.PriorPosition(), Eigen::Vector3d(1.5, -2, 3.25));
  EXPECT_FALSE(database.ReadImageWithName("a.png")->PriorPosition().has_value());
  // A full pose prior's position is its camera centre.
  DatabaseImage posed;
  posed.cam_from_world_prior =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())),
              Eigen::Vector3d(1, 2, 3));
  EXPECT_LT((*posed.PriorPosition() - posed.cam_from_world_prior->Inverse().translation).norm(),
            1e-15);
}

TEST(PosePriorImporter, ImportsAllOrNothingAndNamesTheFault) {
  testing::TempDir dir;
  const fs::path path = ThreeImageDatabase(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    PosePriorImporterOptions options;
    options.database_path = path.string();
    options.input_path = (dir / name).string();
    return options;
  };
  const auto message = [](const PosePriorImporterOptions& options) {
    try {
      RunPosePriorImporter(options, NoProgress());
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // An unknown image, after a good line: nothing stored.
  const std::string unknown = message(write("unknown.txt", "a.png 1 2 3\nzzz.png 4 5 6\n"));
  EXPECT_NE(unknown.find("zzz.png"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("unknown.txt"), std::string::npos) << unknown;
  EXPECT_EQ(RawPriorColumns(path, "a.png"), "NULL NULL NULL NULL NULL NULL NULL");
  // A malformed line names the file and line.
  const std::string malformed = message(write("bad.txt", "# nav\n\na.png 1 2\n"));
  EXPECT_NE(malformed.find("bad.txt:3"), std::string::npos) << malformed;
  EXPECT_NE(message(write("nan.txt", "a.png 1 nan 2\n")).find("nan.txt:1"), std::string::npos);
  EXPECT_NE(message(write("twice.txt", "a.png 1 2 3\na.png 1 2 3\n")).find("twice"),
            std::string::npos);

  const PosePriorImporterSummary summary = RunPosePriorImporter(
      write("nav.txt", "# NAME X Y Z\na.png 1 2 3\nc.png -1 0.5 2\n"), NoProgress());
  EXPECT_EQ(summary.num_imported, 2);
  EXPECT_EQ(summary.num_images_without, 1);
  EXPECT_EQ(RawPriorColumns(path, "c.png"), "NULL NULL NULL NULL -1.000000 0.500000 2.000000");
  // Rerunning is safe.
  EXPECT_EQ(RunPosePriorImporter(write("nav.txt", "a.png 1 2 3\nc.png -1 0.5 2\n"), NoProgress())
                .num_imported,
            2);
}

TEST(SpatialMatching, PairsTheNearestImagesWithinTheDistance) {
  // Two survey lines 0.45 m apart, frames every 0.5 m; the vehicle bobs 1 m
  // in z on the second, which ignore_z discards.
  std::vector<std::pair<image_t, Eigen::Vector3d>> positions;
  for (int k = 0; k < 10; ++k) {
    positions.emplace_back(1 + k, Eigen::Vector3d(0.5 * k, 0, 2));
    positions.emplace_back(11 + k, Eigen::Vector3d(0.5 * k, 0.45, 2 + (k % 2)));
  }
  SpatialPairingOptions options;
  options.max_num_neighbors = 3;
  options.max_distance_m = 0.6;
  const auto pairs = SpatialPairs(positions, options);
  std::set<std::pair<image_t, image_t>> unique;
  for (const auto& [a, b] : pairs) unique.insert({std::min(a, b), std::max(a, b)});
  // Each image: its along-track neighbours (0.5 m) and the one beside it
  // (0.45 m); the diagonal (0.67 m) is too far.
  EXPECT_TRUE(unique.count({1, 11}));
  EXPECT_TRUE(unique.count({1, 2}));
  EXPECT_FALSE(unique.count({1, 12}));
  EXPECT_EQ(unique.size(), 9u + 9u + 10u);
  for (const auto& [a, b] : pairs) EXPECT_NE(a, b);
  options.ignore_z = false;
  std::set<std::pair<image_t, image_t>> with_z;
  for (const auto& [a, b] : SpatialPairs(positions, options))
    with_z.insert({std::min(a, b), std::max(a, b)});
  EXPECT_FALSE(with_z.count({12, 13}));  // 1 m apart in z
}

// A lawnmower survey 2 m over a rough seabed behind a flat port tilted
// 3 deg, observed exactly plus Gaussian pixel noise; the reconstruction is
// handed over in an arbitrary frame (scaled, turned, shifted) under an
// untilted port guess with half the distance.
struct SyntheticSurvey {
  SfmInputs inputs;
  std::map<image_t, Rigid3d> true_cam_from_world;
  std::vector<std::pair<Eigen::Vector3d, std::vector<TrackElement>>> true_points;
  Housing true_housing = Housing::FromName(
      "FLATPORT", {0.0523360, 0.0, 0.9986295, 0.02, 0.01, 1.0, 1.473, 1.334}, "t");
  Camera camera = Camera::FromModelName("PINHOLE", 700, 960, 540);

  SyntheticSurvey(double pixel_sigma, double navigation_sigma, std::mt19937* rng) {
    camera.camera_id = 1;
    inputs.cameras[1] = HousedCamera{camera, true_housing};
    std::normal_distribution<double> noise(0.0, 1.0);
    image_t id = 1;
    const Eigen::Quaterniond down(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
    for (int line = 0; line < 3; ++line) {
      for (int k = 0; k < 8; ++k, ++id) {
        const Eigen::Vector3d centre(0.5 * k, 0.45 * line, 2.0 + 0.05 * std::sin(k));
        true_cam_from_world[id] = Rigid3d(down, -(down * centre));
        SfmImage& image = inputs.images[id];
        image.image_id = id;
        image.name = "img_" + std::to_string(id) + ".png";
        image.camera_id = 1;
        image.position_prior =
            centre + navigation_sigma * Eigen::Vector3d(noise(*rng), noise(*rng), noise(*rng));
      }
    }
    std::uniform_real_distribution<double> x(-1.0, 4.5), y(-0.8, 1.7);
    for (int p = 0; p < 2500; ++p) {
      const double px = x(*rng), py = y(*rng);
      const Eigen::Vector3d world(px, py, 0.15 * std::sin(2 * px) * std::cos(1.5 * py));
      std::vector<TrackElement> track;
      for (auto& [image_id, pose] : true_cam_from_world) {
        const auto pixel = ProjectPoint(camera, &true_housing, pose * world);
        if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > 960 || pixel->y() > 540)
          continue;
        SfmImage& image = inputs.images.at(image_id);
        track.push_back({image_id, static_cast<point2D_t>(image.keypoints.size())});
        image.keypoints.push_back(*pixel + pixel_sigma * Eigen::Vector2d(noise(*rng), noise(*rng)));
      }
      if (track.size() >= 2) true_points.emplace_back(world, track);
    }
    for (auto& [image_id, image] : inputs.images)
      image.correspondences.resize(image.keypoints.size());
  }

  Reconstruction InArbitraryFrame(const Similarity3d& arbitrary_from_true) const {
    std::map<camera_t, HousedCamera> guess = inputs.cameras;
    guess.at(1).housing->params = {0, 0, 1, 0.01, 0.01, 1.0, 1.473, 1.334};
    Reconstruction r(&inputs, guess);
    const Similarity3d& s = arbitrary_from_true;
    for (const auto& [id, pose] : true_cam_from_world) {
      const Eigen::Quaterniond rotation = pose.rotation * s.rotation.conjugate();
      r.Register(id, Rigid3d(rotation, s.scale * pose.translation - rotation * s.translation));
    }
    for (const auto& [xyz, track] : true_points)
      r.AddPoint(s.scale * (s.rotation * xyz) + s.translation, track);
    return r;
  }
};

Similarity3d ArbitraryFrame() {
  Similarity3d s;
  s.scale = 0.6;
  s.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized()));
  s.translation = Eigen::Vector3d(5, -3, 10);
  return s;
}

TEST(PositionPriors, AlignmentUndoesTheArbitraryFrameAndIgnoresAJump) {
  std::mt19937 rng(5);
  SyntheticSurvey survey(0.0, 0.0, &rng);
  survey.inputs.images.at(7).position_prior->x() += 3.0;  // a navigation jump
  Reconstruction r = survey.InArbitraryFrame(ArbitraryFrame());
  const auto alignment = AlignToPositionPriors(&r, 0.05);
  ASSERT_TRUE(alignment.has_value());
  EXPECT_EQ(alignment->num_priors, 24);
  EXPECT_EQ(alignment->num_inliers, 23);
  EXPECT_NEAR(alignment->new_from_old.scale, 1 / 0.6, 1e-9);
  EXPECT_LT(alignment->rms_m, 1e-9);
  for (const auto& [id, pose] : r.poses()) {
    EXPECT_LT((pose.Inverse().translation - survey.true_cam_from_world.at(id).Inverse().translation)
                  .norm(),
              1e-9);
    EXPECT_LT(pose.rotation.angularDistance(survey.true_cam_from_world.at(id).rotation), 1e-9);
  }
  size_t k = 0;
  for (const auto& [point_id, point] : r.points())
    EXPECT_LT((point.xyz - survey.true_points[k++].first).norm(), 1e-9);
  // Collinear priors fix no similarity: nothing changes.
  SyntheticSurvey line(0.0, 0.0, &rng);
  for (auto& [id, image] : line.inputs.images) {
    image.position_prior->y() = 0;
    image.position_prior->z() = 2;
  }
  Reconstruction r2 = line.InArbitraryFrame(ArbitraryFrame());
  const Rigid3d before = r2.poses().begin()->second;
  EXPECT_FALSE(AlignToPositionPriors(&r2, 0.05).has_value());
  EXPECT_EQ(r2.poses().begin()->second.translation, before.translation);
}

TEST(PositionPriors, GiveTheScaleThatSelfCalibratesTheFlatPortDistance) {
  std::mt19937 rng(11);
  const double navigation_sigma = 0.02;
  SyntheticSurvey survey(0.1, navigation_sigma, &rng);
  Reconstruction r = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&r, 5 * navigation_sigma).has_value());
  BundleAdjustmentOptions ba;
  ba.refine_housing = true;
  ba.sigma_px = 0.1;
  ba.position_prior_sigma_m = navigation_sigma;
  ba.max_num_iterations = 200;
  AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale());
  CalibrationStdDevs std_devs;
  AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale(), &std_devs);
  const std::vector<double>& h = r.cameras().at(1).housing->params;
  const std::vector<double>& sd = std_devs.housing.at(1);
  const std::vector<double>& t = survey.true_housing.params;
  // Errors within 4 standard deviations, and the deviations small enough to
  // mean something (the guess was 10 mm and 3 deg off): refraction observes
  // the port distance only through how the rays' virtual centres move with
  // the angle, a fraction of a pixel here, so a survey needs many points.
  for (int k : {0, 1, 3}) EXPECT_LT(std::abs(h[k] - t[k]), 4 * sd[k]) << "parameter " << k;
  EXPECT_LT(sd[3], 0.005);
  EXPECT_LT(sd[0], 0.0015);
  for (const auto& [id, pose] : r.poses()) {
    const Eigen::Vector3d error =
        pose.Inverse().translation - survey.true_cam_from_world.at(id).Inverse().translation;
    EXPECT_LT(error.norm(), 4 * navigation_sigma) << "image " << id;
  }
}

// Moves 2 % of the survey's keypoints 3 px in a random direction; returns
// how many.
int AddOutliers(SyntheticSurvey* survey, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(0, 1);
  int num_outliers = 0;
  for (auto& [id, image] : survey->inputs.images) {
    for (Eigen::Vector2d& keypoint : image.keypoints) {
      if (uniform(*rng) >= 0.02) continue;
      const double angle = 2 * M_PI * uniform(*rng);
      keypoint += 3.0 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      ++num_outliers;
    }
  }
  return num_outliers;
}

// The adjustment of a survey with outliers (AddOutliers): the port
// refined, the keypoints' noise at the loss's scale, the priors the gauge.
BundleAdjustmentOptions OutlierSurveyOptions(double navigation_sigma) {
  BundleAdjustmentOptions ba;
  ba.refine_housing = true;
  ba.sigma_px = 0.1;
  ba.position_prior_sigma_m = navigation_sigma;
  ba.max_num_iterations = 500;
  return ba;
}

// `other` ends where `robust` (with `std_devs`) does: the port within a
// tenth of its standard deviations, the camera centres within a tenth of
// how far the robust solve's lie from the truth.
void ExpectSameSolution(const SyntheticSurvey& survey, const Reconstruction& robust,
                        const CalibrationStdDevs& std_devs, const Reconstruction& other) {
  const std::vector<double>& a = robust.cameras().at(1).housing->params;
  const std::vector<double>& b = other.cameras().at(1).housing->params;
  const std::vector<double>& sd = std_devs.housing.at(1);
  for (int k : {0, 1, 3}) EXPECT_LT(std::abs(a[k] - b[k]), 0.1 * sd[k]) << "parameter " << k;
  double worst_error = 0, worst_difference = 0;
  for (const auto& [id, pose] : robust.poses()) {
    const Eigen::Vector3d centre = pose.Inverse().translation;
    worst_error = std::max(
        worst_error, (centre - survey.true_cam_from_world.at(id).Inverse().translation).norm());
    worst_difference =
        std::max(worst_difference, (centre - other.poses().at(id).Inverse().translation).norm());
  }
  EXPECT_LT(worst_difference, 0.1 * worst_error);
}

// A stop asked for (SIGINT) ends a running adjustment at its next
// iteration as Cancelled, not as a failed solve, and nothing is written back.
TEST(PositionPriors, AStopEndsAnAdjustmentAsCancelled) {
  std::mt19937 rng(11);
  SyntheticSurvey survey(0.1, 0.02, &rng);
  Reconstruction r = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&r, 0.1).has_value());
  BundleAdjustmentOptions ba;
  ba.refine_housing = true;
  ba.position_prior_sigma_m = 0.02;
  const Rigid3d before = r.poses().begin()->second;
  CancelFlag::Request();
  EXPECT_THROW(AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale()), Cancelled);
  CancelFlag::Reset();
  EXPECT_EQ(r.poses().begin()->second.translation, before.translation);
}

// The refinement's schedule (refractive_bundle_adjuster's hold_weights):
// a robust solve to 1e-6 decides the weights, a solve holding them runs to
// 1e-8. With the pixel noise at the loss's scale half the residuals sit in
// the Cauchy loss's transition region, where the robust solve converges
// linearly (docs/benchmarks.md: 138 iterations here); 2 % of the
// observations are 3 px off, so the weights matter. Holding the weights
// must end where the robust solve ends, well within the standard
// deviations, in a fraction of the iterations.
TEST(PositionPriors, HeldWeightsEndTheRobustCrawlAtTheSameSolution) {
  std::mt19937 rng(11);
  const double navigation_sigma = 0.02;
  SyntheticSurvey survey(0.1, navigation_sigma, &rng);
  ASSERT_GT(AddOutliers(&survey, &rng), 100);
  const BundleAdjustmentOptions ba = OutlierSurveyOptions(navigation_sigma);
  const auto adjust = [&](Reconstruction* r, double tolerance, bool hold,
                          CalibrationStdDevs* std_devs) {
    BundleAdjustmentOptions options = ba;
    options.function_tolerance = tolerance;
    options.hold_loss_weights = hold;
    const ceres::Solver::Summary summary =
        AdjustBundle(r, options, BundleAdjustmentScope(), nullptr, MarkerScale(), std_devs);
    EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);
    return static_cast<int>(summary.iterations.size());
  };
  // Both from where a robust solve to 1e-6 ends (from the guess: ~40
  // iterations), as the refinement's final solve starts from its first.
  Reconstruction robust = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&robust, 5 * navigation_sigma).has_value());
  adjust(&robust, 1e-6, false, nullptr);
  Reconstruction held = robust;
  CalibrationStdDevs std_devs;
  const int robust_iterations = adjust(&robust, 1e-8, false, &std_devs);
  const int held_iterations = adjust(&held, 1e-8, true, nullptr);
  EXPECT_LT(4 * held_iterations, robust_iterations);
  ExpectSameSolution(survey, robust, std_devs, held);
  const std::vector<double>& a = robust.cameras().at(1).housing->params;
  const std::vector<double>& b = held.cameras().at(1).housing->params;
  const std::vector<double>& sd = std_devs.housing.at(1);
  // The weights held are the loss's: without them the outliers pull the
  // port further from the truth than the robust solve's.
  Reconstruction plain = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&plain, 5 * navigation_sigma).has_value());
  BundleAdjustmentOptions least_squares = ba;
  least_squares.loss_scale = 0;
  AdjustBundle(&plain, least_squares, BundleAdjustmentScope(), nullptr, MarkerScale());
  const std::vector<double>& t = survey.true_housing.params;
  EXPECT_GT(std::abs(plain.cameras().at(1).housing->params[3] - t[3]), std::abs(b[3] - t[3]));
  std::cout << "robust " << robust_iterations << " iterations, held " << held_iterations
            << "; port distance " << a[3] << " / " << b[3] << " / least squares "
            << plain.cameras().at(1).housing->params[3] << " (truth " << t[3] << ", sd " << sd[3]
            << ")\n";
}

// The robust solve's task in that schedule is to decide the weights, and the
// weights' own settling says when it is done, whatever the survey's length
// (the relative cost change does not: docs/scale.md). Ended there (at most
// 1 % of the weights moved by more than 0.01 in the last step), the held
// solve must land where the robust solve to 1e-8 does, within a tenth of
// the standard deviations, in fewer robust iterations than the 1e-6 stop
// takes.
TEST(PositionPriors, RobustSolveEndsWhenTheWeightsSettle) {
  std::mt19937 rng(11);
  const double navigation_sigma = 0.02;
  SyntheticSurvey survey(0.1, navigation_sigma, &rng);
  ASSERT_GT(AddOutliers(&survey, &rng), 100);
  const BundleAdjustmentOptions ba = OutlierSurveyOptions(navigation_sigma);
  Reconstruction start = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&start, 5 * navigation_sigma).has_value());

  Reconstruction settled = start;
  BundleAdjustmentOptions decide = ba;
  decide.function_tolerance = 1e-12;  // only the weights end it
  decide.max_unsettled_weight_fraction = 0.01;
  const ceres::Solver::Summary decided =
      AdjustBundle(&settled, decide, BundleAdjustmentScope(), nullptr, MarkerScale());
  EXPECT_EQ(decided.termination_type, ceres::USER_SUCCESS);
  // The held solve from there, as the refinement and the mapper's final
  // adjustment run it: undamped at first, Gauss-Newton on a weighted
  // least-squares problem near its minimum, it converges in a few steps.
  const ceres::Solver::Summary held =
      AdjustBundle(&settled, ba.WithWeightsHeld(kHeldWeightsTrustRegionRadius),
                   BundleAdjustmentScope(), nullptr, MarkerScale());
  EXPECT_EQ(held.termination_type, ceres::CONVERGENCE);
  EXPECT_LE(held.iterations.size(), 4u);

  Reconstruction robust = start;
  BundleAdjustmentOptions to_1e6 = ba;
  to_1e6.function_tolerance = 1e-6;
  const int iterations_to_1e6 = static_cast<int>(
      AdjustBundle(&robust, to_1e6, BundleAdjustmentScope(), nullptr, MarkerScale())
          .iterations.size());
  EXPECT_LT(decided.iterations.size(), iterations_to_1e6);
  CalibrationStdDevs std_devs;
  AdjustBundle(&robust, ba, BundleAdjustmentScope(), nullptr, MarkerScale(), &std_devs);

  ExpectSameSolution(survey, robust, std_devs, settled);
  std::cout << "weights settled after " << decided.iterations.size()
            << " robust iterations (1e-6 stop: " << iterations_to_1e6 << "), held solve "
            << held.iterations.size() << " iterations; port distance "
            << settled.cameras().at(1).housing->params[3] << " / robust "
            << robust.cameras().at(1).housing->params[3] << " (sd " << std_devs.housing.at(1)[3]
            << ")\n";
}

// A bounded port (the distance's floor) would make Ceres run a projected
// line search on every step: a cost evaluation at its trial point on top of
// the candidate's (with Ceres' default cubic interpolation a second
// Jacobian: 9 s of each 21 s iteration on a 1000-image survey), and on an
// overshooting step an accepted crawl in place of a rejection. Off: one
// Jacobian per accepted step, one cost evaluation per step, the bound kept.
TEST(PositionPriors, BoundedPortAdjustmentRunsNoLineSearch) {
  std::mt19937 rng(11);
  SyntheticSurvey survey(0.1, 0.02, &rng);
  Reconstruction r = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&r, 0.1).has_value());
  BundleAdjustmentOptions ba;
  ba.refine_housing = true;
  ba.sigma_px = 0.1;
  ba.position_prior_sigma_m = 0.02;
  ba.max_num_iterations = 10;
  const ceres::Solver::Summary summary =
      AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale());
  ASSERT_TRUE(summary.is_constrained);
  ASSERT_GT(summary.num_successful_steps, 3);
  EXPECT_EQ(summary.num_line_search_steps, 0);
  EXPECT_EQ(summary.line_search_total_time_in_seconds, 0.0);
  // One at the start and one per step.
  const int num_steps = summary.num_successful_steps + summary.num_unsuccessful_steps;
  EXPECT_LE(summary.num_jacobian_evaluations, summary.num_successful_steps + 1);
  EXPECT_LE(summary.num_residual_evaluations, num_steps + 1);
  EXPECT_GE(r.cameras().at(1).housing->params[3], 1e-4);
}

// A point moved inside the port's outer surface (as rescaling a model with
// a port self-calibrated far out does) cannot be projected: an adjustment
// starting there fails and names the observation, and aligning the model
// to the priors again (DeleteUnprojectableObservations at its end) takes
// out just the observations that cannot be projected, after which the
// adjustment runs.
TEST(PositionPriors, UnprojectableObservationIsNamedAndDeleted) {
  std::mt19937 rng(11);
  SyntheticSurvey survey(0.1, 0.02, &rng);
  Reconstruction r = survey.InArbitraryFrame(ArbitraryFrame());
  ASSERT_TRUE(AlignToPositionPriors(&r, 0.1).has_value());
  const point3D_t moved = r.points().begin()->first;
  const TrackElement seen = r.points().at(moved).track.front();
  // 5 mm in front of the lens, the port's outer surface at 2 cm.
  r.point(moved).xyz = r.poses().at(seen.image_id).Inverse() * Eigen::Vector3d(0, 0, 0.005);
  ASSERT_TRUE(std::isinf(r.ReprojectionError(seen.image_id, seen.point2D_idx, r.point(moved).xyz)));
  size_t num_observations = 0, num_unprojectable = 0;
  for (const auto& [id, point] : r.points()) {
    for (const TrackElement& e : point.track) {
      ++num_observations;
      num_unprojectable +=
          !std::isfinite(r.ReprojectionError(e.image_id, e.point2D_idx, point.xyz));
    }
  }
  ASSERT_LT(num_unprojectable, r.points().at(moved).track.size() + 1);
  BundleAdjustmentOptions ba;
  ba.refine_housing = true;
  ba.sigma_px = 0.1;
  ba.position_prior_sigma_m = 0.02;
  ba.max_num_iterations = 5;
  const std::string name = survey.inputs.images.at(seen.image_id).name;
  try {
    AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale());
    ADD_FAILURE() << "the adjustment started from an unprojectable observation";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("the observation of 3D point " + std::to_string(moved) +
                                         " in image '" + name + "'"),
              std::string::npos)
        << e.what();
  }
  const auto realigned = AlignToPositionPriors(&r, 0.1);
  ASSERT_TRUE(realigned.has_value());
  EXPECT_EQ(realigned->num_unprojectable_deleted, static_cast<int>(num_unprojectable));
  EXPECT_EQ(r.DeleteUnprojectableObservations(), 0);
  EXPECT_EQ(r.PointOf(seen.image_id, seen.point2D_idx), kInvalidPoint3DId);
  size_t num_left = 0;
  for (const auto& [id, point] : r.points()) num_left += point.track.size();
  // The moved point goes whole if fewer than two observations are left.
  const size_t expected = num_observations - num_unprojectable;
  EXPECT_TRUE(num_left == expected || (num_left + 1 == expected && !r.points().count(moved)))
      << num_left;
  EXPECT_NO_THROW(AdjustBundle(&r, ba, BundleAdjustmentScope(), nullptr, MarkerScale()));
}

}  // namespace
}  // namespace portcal
