// Flat and dome ports: exact forward projection (1e-9 px), Snell's law,
// total internal reflection, validation, and autodiff derivatives.
#include "colmap_ext/housing/housing.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {
namespace {

Camera TestCamera() {
  Camera camera = Camera::FromModelName("RADIAL", 1297.3655, 1920, 1080);
  camera.params = {1297.3655, 961.3, 538.2, -0.05, 0.01};
  return camera;
}

std::vector<Housing> TestHousings() {
  const double tilt = 5.0 * M_PI / 180.0;
  Eigen::Vector3d oblique(0.05, -0.03, 1.0);
  oblique.normalize();
  return {
      Housing::FromName(
          "FLATPORT", {std::sin(tilt), 0, std::cos(tilt), 0.02, 0.014, 1.0, 1.473, 1.334}, "test"),
      Housing::FromName("FLATPORT",
                        {oblique.x(), oblique.y(), oblique.z(), 0.005, 0.01, 1.0, 1.49, 1.333},
                        "test"),
      Housing::FromName("DOMEPORT", {0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334}, "test"),
      Housing::FromName("DOMEPORT", {0.0, 0.0, -0.0073, 0.043552, 0.00375, 1.0, 1.495, 1.333},
                        "test"),
      Housing::FromName("DOMEPORT", {0, 0, 0, 0.05, 0.006, 1.0, 1.473, 1.334}, "test"),
  };
}

std::vector<Eigen::Vector2d> PixelGrid() {
  std::vector<Eigen::Vector2d> pixels;
  for (double x = 0.5; x < 1920; x += 95.7) {
    for (double y = 0.5; y < 1080; y += 67.3) pixels.emplace_back(x, y);
  }
  pixels.emplace_back(961.3, 538.2);  // the principal point
  return pixels;
}

TEST(Housing, UnprojectThenProjectReturnsThePixel) {
  const Camera camera = TestCamera();
  for (const Housing& housing : TestHousings()) {
    double max_error = 0;
    for (const Eigen::Vector2d& pixel : PixelGrid()) {
      const std::optional<Ray3d> ray = UnprojectPixel(camera, &housing, pixel);
      ASSERT_TRUE(ray) << housing.ModelName() << " " << pixel.transpose();
      EXPECT_NEAR(ray->direction.norm(), 1.0, 1e-14);
      for (const double depth : {0.05, 0.5, 1.0, 4.0, 30.0}) {
        const Eigen::Vector3d point = ray->origin + depth * ray->direction;
        const std::optional<Eigen::Vector2d> projected = ProjectPoint(camera, &housing, point);
        ASSERT_TRUE(projected) << housing.ModelName() << " depth " << depth;
        max_error = std::max(max_error, (*projected - pixel).norm());
      }
    }
    EXPECT_LT(max_error, 1e-9)
        << housing.ModelName() << " "
        << Eigen::Map<const Eigen::VectorXd>(housing.params.data(), 8).transpose();
  }
}

// n1 sin(theta1) is conserved across parallel interfaces: the tangential
// component of the direction, times the index, is the same in air and water.
TEST(Housing, FlatPortObeysSnellsLaw) {
  const Housing housing = TestHousings()[0];
  const Eigen::Vector3d n(housing.params[0], housing.params[1], housing.params[2]);
  for (const Eigen::Vector3d& dir_air :
       {Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector3d(-0.7, 0.4, 1.0),
        Eigen::Vector3d(0.0, 0.0, 1.0)}) {
    Eigen::Vector3d origin, dir_water;
    ASSERT_TRUE(FlatPort::RayInWater(housing.params.data(), dir_air, &origin, &dir_water));
    const Eigen::Vector3d d = dir_air.normalized();
    const Eigen::Vector3d tangential_air = 1.0 * (d - d.dot(n) * n);
    const Eigen::Vector3d tangential_water = 1.334 * (dir_water - dir_water.dot(n) * n);
    EXPECT_LT((tangential_air - tangential_water).norm(), 1e-15);
    EXPECT_NEAR(n.dot(origin), 0.02 + 0.014, 1e-15);  // on the outer surface
  }
}

TEST(Housing, DomeRayStartsOnTheOuterSphere) {
  const Housing housing = TestHousings()[2];
  const Eigen::Vector3d center(0.01, 0.006, 0.002);
  Eigen::Vector3d origin, dir_water;
  ASSERT_TRUE(DomePort::RayInWater(housing.params.data(), Eigen::Vector3d(0.4, 0.3, 1.0), &origin,
                                   &dir_water));
  EXPECT_NEAR((origin - center).norm(), 0.056, 1e-15);
}

TEST(Housing, ConcentricDomeDoesNotBendRaysThroughItsCentre) {
  const Camera camera = TestCamera();
  const Housing housing = TestHousings()[4];
  const Eigen::Vector3d point(0.3, -0.2, 1.5);
  const std::optional<Eigen::Vector2d> with_dome = ProjectPoint(camera, &housing, point);
  const std::optional<Eigen::Vector2d> in_air = camera.ImgFromCam(point);
  ASSERT_TRUE(with_dome && in_air);
  EXPECT_LT((*with_dome - *in_air).norm(), 1e-9);
}

TEST(Housing, TotalInternalReflectionIsReportedNotNaN) {
  // Denser medium inside than outside: rays beyond asin(1/1.333) = 48.6 deg
  // are totally reflected.
  const Housing housing =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.02, 0.01, 1.333, 1.5, 1.0}, "tir");
  Eigen::Vector3d origin, dir;
  EXPECT_TRUE(FlatPort::RayInWater(housing.params.data(), Eigen::Vector3d(std::tan(0.8), 0, 1),
                                   &origin, &dir));
  EXPECT_FALSE(FlatPort::RayInWater(housing.params.data(), Eigen::Vector3d(std::tan(0.9), 0, 1),
                                    &origin, &dir));
  Camera camera = Camera::FromModelName("PINHOLE", 300, 1920, 1080);
  EXPECT_FALSE(UnprojectPixel(camera, &housing, Eigen::Vector2d(1900, 540)));
  // Any point beyond the port is still reached, by a ray just below the
  // critical angle (grazing in water): its pixel is finite and back-projects
  // to a ray through the point.
  const Eigen::Vector3d point(10.0, 0, 0.5);
  const auto pixel = ProjectPoint(camera, &housing, point);
  ASSERT_TRUE(pixel.has_value());
  ASSERT_TRUE(pixel->allFinite());
  const auto ray = UnprojectPixel(camera, &housing, *pixel);
  ASSERT_TRUE(ray.has_value());
  const Eigen::Vector3d to_point = point - ray->origin;
  EXPECT_LT((to_point - to_point.dot(ray->direction) * ray->direction).norm(), 1e-9);
}

TEST(Housing, PointsInsideTheHousingDoNotProject) {
  const Camera camera = TestCamera();
  const std::vector<Housing> housings = TestHousings();
  EXPECT_FALSE(ProjectPoint(camera, &housings[0], Eigen::Vector3d(0, 0, 0.03)));
  EXPECT_FALSE(ProjectPoint(camera, &housings[2], Eigen::Vector3d(0, 0, 0.05)));
  EXPECT_FALSE(ProjectPoint(camera, &housings[0], Eigen::Vector3d(0, 0, -1)));
}

TEST(Housing, ValidationNamesTheProblem) {
  const auto message = [](const std::string& model, std::vector<double> params) {
    try {
      Housing::FromName(model, std::move(params), "housings.txt:3");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("FLATPORT", {0, 0, 2, 0.02, 0.01, 1, 1.5, 1.33}).find("unit"),
            std::string::npos);
  EXPECT_NE(message("FLATPORT", {0, 0, 1, -0.02, 0.01, 1, 1.5, 1.33}).find("int_dist"),
            std::string::npos);
  EXPECT_NE(message("DOMEPORT", {0.06, 0, 0, 0.05, 0.01, 1, 1.5, 1.33}).find("inside"),
            std::string::npos);
  EXPECT_NE(message("DOMEPORT", {0, 0, 0, 0.05}).find("8 parameters"), std::string::npos);
  EXPECT_NE(message("BALLPORT", {}).find("BALLPORT"), std::string::npos);
  EXPECT_NE(message("DOMEPORT", {0, 0, 0, 0.05, 0.01, 1, 1.5, 1.33}), "x");
  EXPECT_EQ(message("DOMEPORT", {0, 0, 0, 0.05, 0.01, 1, 1.5, 1.33}), "");
  EXPECT_NE(
      message("FLATPORT", {0, 0, 1, 0.02, 0.01, 1, std::nan(""), 1.33}).find("housings.txt:3"),
      std::string::npos);
}

// d(pixel)/d(intrinsics, housing, point) of the exact forward projection by
// autodiff against central differences.
template <typename Port>
void CheckProjectionDerivatives(const Camera& camera, const Housing& housing,
                                const Eigen::Vector3d& point) {
  constexpr int kCam = RadialModel::kNumParams;
  constexpr int kPort = Port::kNumParams;
  constexpr int kAll = kCam + kPort + 3;
  using Jet = ceres::Jet<double, kAll>;
  Jet intrinsics[kCam], port[kPort];
  for (int i = 0; i < kCam; ++i) intrinsics[i] = Jet(camera.params[i], i);
  for (int i = 0; i < kPort; ++i) port[i] = Jet(housing.params[i], kCam + i);
  VectorT<Jet, 3> point_jet;
  for (int i = 0; i < 3; ++i) point_jet[i] = Jet(point[i], kCam + kPort + i);
  Jet x, y;
  ASSERT_TRUE((ImgFromWater<RadialModel, Port, Jet>(intrinsics, port, point_jet, &x, &y)));

  for (int k = 0; k < kAll; ++k) {
    std::vector<double> cam_p = camera.params, port_p = housing.params;
    Eigen::Vector3d point_p = point;
    const auto eval = [&](double delta, Eigen::Vector2d* pixel) {
      std::vector<double> c = cam_p, h = port_p;
      Eigen::Vector3d X = point_p;
      if (k < kCam)
        c[k] += delta;
      else if (k < kCam + kPort)
        h[k - kCam] += delta;
      else
        X[k - kCam - kPort] += delta;
      return ImgFromWater<RadialModel, Port, double>(c.data(), h.data(), X, &pixel->x(),
                                                     &pixel->y());
    };
    const double h = k < kCam ? 1e-6 * std::max(1.0, std::abs(camera.params[k])) : 1e-7;
    Eigen::Vector2d plus, minus;
    ASSERT_TRUE(eval(h, &plus) && eval(-h, &minus));
    const Eigen::Vector2d numeric = (plus - minus) / (2 * h);
    const double tolerance = 1e-5 * (1.0 + numeric.norm());
    EXPECT_NEAR(x.v[k], numeric.x(), tolerance) << Port::kName << " d/d" << k;
    EXPECT_NEAR(y.v[k], numeric.y(), tolerance) << Port::kName << " d/d" << k;
  }
}

TEST(Housing, ImplausibleButValidHousingsSayWhy) {
  // Within the bounds: a port 3 cm away tilted 5 deg, a dome off by 5 mm.
  const double tilt = 5.0 * M_PI / 180.0;
  EXPECT_FALSE(Housing::FromName("FLATPORT",
                                 {std::sin(tilt), 0, std::cos(tilt), 0.03, 0.008, 1, 1.473, 1.334},
                                 "t")
                   .Implausibility());
  EXPECT_FALSE(
      Housing::FromName("DOMEPORT", {0.003, -0.002, 0.004, 0.05, 0.006, 1, 1.473, 1.334}, "t")
          .Implausibility());
  // Issue 21's wrong basins: 361 mm away; tilted 11.4 deg; a dome 15 mm off.
  const auto why_flat =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.361, 0.008, 1, 1.473, 1.334}, "t").Implausibility();
  ASSERT_TRUE(why_flat);
  EXPECT_NE(why_flat->find("361.0 mm"), std::string::npos) << *why_flat;
  const double wrong = 11.4 * M_PI / 180.0;
  const auto why_tilt =
      Housing::FromName("FLATPORT",
                        {std::sin(wrong), 0, std::cos(wrong), 0.03, 0.008, 1, 1.473, 1.334}, "t")
          .Implausibility();
  ASSERT_TRUE(why_tilt);
  EXPECT_NE(why_tilt->find("tilted 11.4 deg"), std::string::npos) << *why_tilt;
  const auto why_dome =
      Housing::FromName("DOMEPORT", {0.0, 0.009, -0.012, 0.05, 0.006, 1, 1.473, 1.334}, "t")
          .Implausibility();
  ASSERT_TRUE(why_dome);
  EXPECT_NE(why_dome->find("15.0 mm"), std::string::npos) << *why_dome;
}

// Lengths in millimetres where portcal takes metres: the real dome's radius
// (43.552 mm) and thickness, a flat port 20 mm away; an error that names
// the parameter and the unit, where the metric values pass.
TEST(Housing, LengthsGivenInMillimetresAreNamed) {
  const auto message = [](const Housing& housing) {
    try {
      housing.ValidateInput("--Housing.params");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const Housing dome{
      Housing::FromName("DOMEPORT", {0, 0, 0, 0.043552, 0.00375, 1, 1.495, 1.333}, "t")};
  EXPECT_EQ(message(dome), "");
  Housing dome_mm = dome;
  dome_mm.params[3] = 43.552;
  dome_mm.params[4] = 3.75;
  EXPECT_NE(message(dome_mm).find(
                "int_radius = 43.552 m: portcal takes metres (43.552 mm is 0.043552 m)"),
            std::string::npos)
      << message(dome_mm);
  Housing centre_mm = dome;
  centre_mm.params[2] = -7.3;  // outside the dome too: the units are named first
  EXPECT_NE(message(centre_mm).find("Cz = -7.3 m: portcal takes metres"), std::string::npos)
      << message(centre_mm);
  const Housing flat{Housing::FromName("FLATPORT", {0, 0, 1, 0.02, 0.014, 1, 1.473, 1.334}, "t")};
  EXPECT_EQ(message(flat), "");
  Housing flat_mm = flat;
  flat_mm.params[3] = 20;
  EXPECT_NE(message(flat_mm).find("int_dist = 20 m"), std::string::npos) << message(flat_mm);
}

// The report says where the port sits in the words of a housing drawing:
// camera frame x right, y down, z forward.
TEST(Housing, InWordsSaysWhereThePortSits) {
  const double tilt = 5.0 * M_PI / 180.0;
  const std::string flat =
      Housing::FromName("FLATPORT",
                        {-std::sin(tilt), 0, std::cos(tilt), 0.02, 0.014, 1, 1.473, 1.334}, "t")
          .InWords();
  EXPECT_NE(flat.find("tilted 5.00 deg from the optical axis (5.00 deg towards the image's left, "
                      "0.00 deg towards"),
            std::string::npos)
      << flat;
  EXPECT_NE(flat.find("20.00 mm in front of"), std::string::npos) << flat;
  const std::string dome =
      Housing::FromName("DOMEPORT", {0.004, -0.002, 0.0073, 0.043552, 0.00375, 1, 1.495, 1.333},
                        "t")
          .InWords();
  EXPECT_NE(
      dome.find("4.00 mm right, 2.00 mm up and 7.30 mm ahead of the camera's projection centre"),
      std::string::npos)
      << dome;
}

TEST(Housing, AtBoundIsTheAdjustmentsFloorOrWall) {
  // A flat port at the 0.1 mm floor of its distance, a dome decentred to
  // 90 % of its radius: bounds, not estimates.
  const auto flat = [](double distance) {
    return Housing::FromName(
        "FLATPORT", {0.05, 0.0, std::sqrt(1 - 0.0025), distance, 0.01, 1, 1.473, 1.334}, "test");
  };
  EXPECT_TRUE(flat(1e-4).AtBound());
  EXPECT_FALSE(flat(0.015).AtBound());
  EXPECT_FALSE(flat(1e-3).AtBound());
  const auto dome = [](double cz) {
    return Housing::FromName("DOMEPORT", {0.01, 0.0, cz, 0.05, 0.006, 1, 1.473, 1.334}, "test");
  };
  EXPECT_TRUE(dome(-0.045).AtBound());
  EXPECT_FALSE(dome(0.02).AtBound());
}

TEST(Housing, RefinementNamesWhatAnAdjustmentMayMoveAndHowFar) {
  const Housing flat =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.03, 0.008, 1, 1.473, 1.334}, "test");
  const HousingRefinement f = flat.Refinement();
  EXPECT_EQ(f.orientation, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(f.position, (std::vector<int>{3}));
  ASSERT_EQ(f.bounds.size(), 1u);
  EXPECT_EQ(f.bounds[0].index, 3);
  EXPECT_EQ(f.bounds[0].lower, 1e-4);
  EXPECT_FALSE(std::isfinite(f.bounds[0].upper));
  EXPECT_EQ(flat.InAirFocalRatio(), 1.0 / 1.334);
  const Housing dome =
      Housing::FromName("DOMEPORT", {0.001, 0, 0, 0.05, 0.006, 1, 1.473, 1.334}, "test");
  const HousingRefinement d = dome.Refinement();
  EXPECT_TRUE(d.orientation.empty());
  EXPECT_EQ(d.position, (std::vector<int>{0, 1, 2}));
  ASSERT_EQ(d.bounds.size(), 3u);
  for (const HousingParamBound& b : d.bounds) {
    EXPECT_DOUBLE_EQ(b.upper, 0.045);
    EXPECT_DOUBLE_EQ(b.lower, -0.045);
  }
  EXPECT_EQ(dome.InAirFocalRatio(), 1.0);
}

// A housing calibration's starts keep the model and the user's constants,
// move only what the model refines, and stay inside the adjustment's bounds.
TEST(Housing, StartCandidatesMoveOnlyTheRefinedParametersWithinTheBounds) {
  const Eigen::Vector3d axis =
      Eigen::Vector3d(0.05, -0.02, -1).normalized();  // sign as the views give it
  for (const Housing& housing :
       {Housing::FromName("FLATPORT", {0, 0, 1, 0.01, 0.008, 1, 1.473, 1.334}, "test"),
        Housing::FromName("DOMEPORT", {0, 0, 0, 0.05, 0.006, 1, 1.473, 1.334}, "test")}) {
    const std::vector<Housing> starts = housing.StartCandidates(axis);
    ASSERT_GE(starts.size(), 10u) << housing.ModelName();
    const HousingRefinement refinement = housing.Refinement();
    for (const Housing& start : starts) {
      EXPECT_TRUE(start.SameModel(housing));
      EXPECT_NO_THROW(start.Validate("start"));
      for (size_t k = 0; k < housing.params.size(); ++k) {
        if (!refinement.IsRefined(static_cast<int>(k))) {
          EXPECT_EQ(start.params[k], housing.params[k])
              << housing.ModelName() << " parameter " << k;
        }
      }
      for (const HousingParamBound& bound : start.Refinement().bounds) {
        EXPECT_GE(start.params[static_cast<size_t>(bound.index)], bound.lower)
            << housing.ModelName();
        EXPECT_LE(start.params[static_cast<size_t>(bound.index)], bound.upper)
            << housing.ModelName();
      }
    }
    if (!refinement.orientation.empty()) {
      // A flat port's normal faces forward, along the axis up to sign.
      const Eigen::Vector3d normal(starts[0].params[0], starts[0].params[1], starts[0].params[2]);
      EXPECT_GT(normal.z(), 0);
      EXPECT_NEAR(std::abs(normal.dot(axis)), 1.0, 1e-12);
    }
  }
}

TEST(Housing, HousedCameraProjectsThroughItsHousingOrInAir) {
  const Eigen::Vector3d point(0.1, -0.05, 0.8);
  for (const Housing& housing : TestHousings()) {
    const HousedCamera housed{TestCamera(), housing};
    EXPECT_EQ(housed.HousingOrNull(), &*housed.housing);
    const auto pixel = housed.Project(point);
    ASSERT_TRUE(pixel);
    EXPECT_EQ(*pixel, *ProjectPoint(housed.camera, &housing, point));
    const auto ray = housed.Unproject(*pixel);
    ASSERT_TRUE(ray);
    EXPECT_EQ(ray->origin, UnprojectPixel(housed.camera, &housing, *pixel)->origin);
  }
  const HousedCamera in_air{TestCamera(), std::nullopt};
  EXPECT_EQ(in_air.HousingOrNull(), nullptr);
  EXPECT_EQ(*in_air.Project(point), *TestCamera().ImgFromCam(point));
}

TEST(Housing, ForwardProjectionDerivativesMatchCentralDifferences) {
  const Camera camera = TestCamera();
  const std::vector<Housing> housings = TestHousings();
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.31, -0.22, 1.4), Eigen::Vector3d(-0.05, 0.4, 0.6)}) {
    CheckProjectionDerivatives<FlatPort>(camera, housings[0], point);
    CheckProjectionDerivatives<FlatPort>(camera, housings[1], point);
    CheckProjectionDerivatives<DomePort>(camera, housings[2], point);
    CheckProjectionDerivatives<DomePort>(camera, housings[3], point);
  }
}

TEST(Housing, ModelListIdsAndNamesAreUnique) {
  EXPECT_EQ(HousingModelNameToId("FLATPORT"), 0);
  EXPECT_EQ(HousingModelNameToId("DOMEPORT"), 1);
  EXPECT_EQ(HousingModelIdToName(0), "FLATPORT");
  EXPECT_EQ(HousingModelIdToName(1), "DOMEPORT");
  EXPECT_THROW(HousingModelIdToName(2), InputError);
}

}  // namespace
}  // namespace portcal
