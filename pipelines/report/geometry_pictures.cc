#include "pipelines/report/geometry_pictures.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/report/picture.h"

namespace portcal {

namespace {

const cv::Scalar kBlack(0, 0, 0), kBlue(180, 90, 20), kRed(40, 40, 210), kGlass(200, 160, 90);

// A plane of the camera frame: which two axes a view shows (the second
// drawn upwards) and how it is named.
struct View2d {
  int horizontal, vertical;
  double vertical_sign;  // -1: y down drawn downwards
  const char* axes;
  Eigen::Vector2d operator()(const Eigen::Vector3d& p) const {
    return Eigen::Vector2d(p[horizontal], vertical_sign * p[vertical]);
  }
};
constexpr View2d kFromAbove{0, 2, 1.0, "from above: x right, z forward (up)"};
constexpr View2d kFromSide{2, 1, -1.0, "from the side: z forward (right), y down"};

void DrawCameraCentre(PlanCanvas* canvas, const View2d& view, double axis_length) {
  const cv::Point centre = (*canvas)(view(Eigen::Vector3d::Zero()));
  cv::arrowedLine(canvas->image(), centre, (*canvas)(view(Eigen::Vector3d(0, 0, axis_length))),
                  kBlack, 1, cv::LINE_AA, 0, 0.08);
  cv::circle(canvas->image(), centre, 4, kBlack, cv::FILLED, cv::LINE_AA);
  DrawLabel(&canvas->image(), "camera", centre + cv::Point(6, 16), 0.45);
}

void DrawPort(DomePort, const double* port, const View2d& view, PlanCanvas* canvas) {
  const Eigen::Vector3d centre = DomePort::Center(port);
  const cv::Point c = (*canvas)(view(centre));
  for (const double radius : {DomePort::InnerRadius(port), DomePort::OuterRadius(port)}) {
    cv::circle(canvas->image(), c, static_cast<int>(std::lround(radius * canvas->PixelsPerMetre())),
               kGlass, 2, cv::LINE_AA);
  }
  cv::arrowedLine(canvas->image(), (*canvas)(view(Eigen::Vector3d::Zero())), c, kRed, 2,
                  cv::LINE_AA, 0, 0.15);
  cv::circle(canvas->image(), c, 3, kBlue, cv::FILLED, cv::LINE_AA);
  // As a legend under the title: beside a centre a few millimetres from the
  // camera's, the label ran over the camera's.
  cv::circle(canvas->image(), cv::Point(14, 44), 3, kBlue, cv::FILLED, cv::LINE_AA);
  DrawLabel(&canvas->image(),
            "dome centre, offset " + FormatFixed(centre.norm() * 1000, 2) + " mm (red arrow)",
            cv::Point(22, 49), 0.45, kRed);
  DrawCameraCentre(canvas, view, DomePort::InnerRadius(port));
}

std::vector<Eigen::Vector3d> DomeExtent(const double* port) {
  const double r = DomePort::OuterRadius(port) * 1.1;
  const Eigen::Vector3d c = DomePort::Center(port);
  return {c + Eigen::Vector3d(-r, -r, -r), c + Eigen::Vector3d(r, r, r), Eigen::Vector3d::Zero()};
}

void DrawPort(FlatPort, const double* port, const View2d& view, PlanCanvas* canvas) {
  const Eigen::Vector3d normal = FlatPort::Normal(port).normalized();
  const double d = FlatPort::InterfaceDistance(port), t = FlatPort::Thickness(port);
  // The glass's two faces where the view's plane cuts them: along the
  // direction in that plane perpendicular to the normal.
  Eigen::Vector3d in_plane = Eigen::Vector3d::Zero();
  in_plane[view.horizontal] = normal[view.vertical];
  in_plane[view.vertical] = -normal[view.horizontal];
  if (in_plane.norm() < 1e-9) in_plane[view.horizontal] = 1;
  in_plane.normalize();
  const double half = 2.5 * (d + t);
  for (const double distance : {d, d + t}) {
    const Eigen::Vector3d foot = normal * distance;
    cv::line(canvas->image(), (*canvas)(view(foot - half * in_plane)),
             (*canvas)(view(foot + half * in_plane)), kGlass, 2, cv::LINE_AA);
  }
  cv::arrowedLine(canvas->image(), (*canvas)(view(Eigen::Vector3d::Zero())),
                  (*canvas)(view(normal * d)), kRed, 2, cv::LINE_AA, 0, 0.12);
  const double tilt_deg = std::acos(std::clamp(normal.z(), -1.0, 1.0)) * 180 / M_PI;
  DrawLabel(&canvas->image(),
            "normal tilted " + FormatFixed(tilt_deg, 2) + " deg, glass at " +
                FormatFixed(d * 1000, 2) + " mm",
            (*canvas)(view(normal * d)) + cv::Point(8, -10), 0.45, kRed);
  DrawCameraCentre(canvas, view, 0.6 * d);
}

std::vector<Eigen::Vector3d> FlatExtent(const double* port) {
  const double reach = 1.6 * (FlatPort::InterfaceDistance(port) + FlatPort::Thickness(port));
  return {Eigen::Vector3d(-reach, -reach, -0.3 * reach), Eigen::Vector3d(reach, reach, reach)};
}

std::vector<Eigen::Vector3d> PortExtent(DomePort, const double* port) { return DomeExtent(port); }
std::vector<Eigen::Vector3d> PortExtent(FlatPort, const double* port) { return FlatExtent(port); }

}  // namespace

cv::Mat HousingPicture(const Housing& housing) {
  std::vector<cv::Mat> panels;
  VisitHousingModel(housing.model_id, [&](auto port_tag) {
    const double* port = housing.params.data();
    for (const View2d& view : {kFromAbove, kFromSide}) {
      std::vector<Eigen::Vector2d> extent;
      for (const Eigen::Vector3d& p : PortExtent(port_tag, port)) extent.push_back(view(p));
      PlanCanvas canvas(extent, 560, 520, housing.ModelName() + std::string(", ") + view.axes);
      DrawPort(port_tag, port, view, &canvas);
      canvas.DrawScaleBar("to scale");
      panels.push_back(canvas.image());
    }
  });
  cv::Mat picture;
  cv::hconcat(panels, picture);
  return picture;
}

namespace {

// A camera from above: its centre, and its field of view's edges.
void DrawCameraFromAbove(PlanCanvas* canvas, const Rigid3d& world_from_cam, double half_fov,
                         double reach, const cv::Scalar& colour, const std::string& name) {
  const Eigen::Vector3d centre = world_from_cam.translation;
  const cv::Point c = (*canvas)(kFromAbove(centre));
  for (const double side : {-1.0, 1.0}) {
    const Eigen::Vector3d edge(side * std::tan(half_fov) * reach, 0, reach);
    cv::line(canvas->image(), c, (*canvas)(kFromAbove(world_from_cam * edge)), colour, 1,
             cv::LINE_AA);
  }
  cv::arrowedLine(canvas->image(), c,
                  (*canvas)(kFromAbove(world_from_cam * Eigen::Vector3d(0, 0, 0.5 * reach))),
                  colour, 2, cv::LINE_AA, 0, 0.1);
  cv::circle(canvas->image(), c, 4, colour, cv::FILLED, cv::LINE_AA);
  DrawLabel(&canvas->image(), name, c + cv::Point(6, 16), 0.45, colour);
}

}  // namespace

cv::Mat RigFromAbovePicture(const Camera& camera1, const Rigid3d& cam2_from_cam1,
                            const std::vector<Rigid3d>& cam1_from_target) {
  const Rigid3d cam1_from_cam2 = cam2_from_cam1.Inverse();
  const double baseline = cam2_from_cam1.translation.norm();
  double reach = 2 * baseline;
  std::vector<Eigen::Vector2d> extent = {kFromAbove(Eigen::Vector3d::Zero()),
                                         kFromAbove(cam1_from_cam2.translation)};
  for (const Rigid3d& pose : cam1_from_target) {
    extent.push_back(kFromAbove(pose.translation));
    reach = std::max(reach, pose.translation.z());
  }
  extent.push_back(Eigen::Vector2d(0, reach));
  PlanCanvas canvas(extent, 760, 560,
                    "Stereo rig from above: baseline " + FormatFixed(baseline * 1000, 2) + " mm, " +
                        std::to_string(cam1_from_target.size()) + " target positions");
  const double half_fov = std::atan(0.5 * camera1.width / camera1.MeanFocalLength());
  for (const Rigid3d& pose : cam1_from_target) {
    cv::circle(canvas.image(), canvas(kFromAbove(pose.translation)), 3, cv::Scalar(120, 120, 120),
               cv::FILLED);
  }
  DrawCameraFromAbove(&canvas, Rigid3d(), half_fov, reach, kBlue, "camera 1");
  DrawCameraFromAbove(&canvas, cam1_from_cam2, half_fov, reach, kRed, "camera 2");
  canvas.DrawScaleBar("camera 1's x right, z forward; grey: the target");
  return canvas.image();
}

cv::Mat SceneFromAbovePicture(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Rigid3d>& cam_from_world,
                              const std::string& title) {
  // The plane of the two widest axes of the cameras and points.
  std::vector<Eigen::Vector3d> all = points;
  for (const Rigid3d& pose : cam_from_world) all.push_back(pose.Inverse().translation);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : all) mean += p;
  mean /= std::max<size_t>(1, all.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : all) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  const Eigen::Vector3d u = eigen.eigenvectors().col(2), v = eigen.eigenvectors().col(1);
  const auto plan = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - mean).dot(u), (p - mean).dot(v));
  };
  std::vector<Eigen::Vector2d> extent;
  for (const Eigen::Vector3d& p : all) extent.push_back(plan(p));
  PlanCanvas canvas(extent, 900, 700, title);
  for (const Eigen::Vector3d& p : points) {
    cv::circle(canvas.image(), canvas(plan(p)), 1, cv::Scalar(90, 90, 90), cv::FILLED);
  }
  const double reach =
      0.04 * std::max(1e-9, (extent.empty() ? 1.0 : 900 / canvas.PixelsPerMetre()));
  for (const Rigid3d& pose : cam_from_world) {
    const Rigid3d world_from_cam = pose.Inverse();
    const cv::Point c = canvas(plan(world_from_cam.translation));
    cv::arrowedLine(canvas.image(), c, canvas(plan(world_from_cam * Eigen::Vector3d(0, 0, reach))),
                    kRed, 1, cv::LINE_AA, 0, 0.3);
    cv::circle(canvas.image(), c, 3, kRed, cv::FILLED, cv::LINE_AA);
  }
  canvas.DrawScaleBar("the reconstruction's two widest axes; red: cameras and their axes");
  return canvas.image();
}

}  // namespace portcal
