#include "pipelines/synthetic/seabed_markers.h"

#include <Eigen/Geometry>
#include <cmath>

#include "colmap_ext/util/error.h"
#include "pipelines/markers/aruco.h"

namespace portcal {

void SeabedMarkerOptions::Check() const {
  if (count < 0) throw OptionError("survey.markers.count", count, ">= 0");
  if (!(side_m > 0)) throw OptionError("survey.markers.side", side_m, "> 0 m");
  if (!(spacing_m > 1.5 * side_m)) {
    throw OptionError("survey.markers.spacing", spacing_m, "> 1.5 x the side (the plates)");
  }
  const cv::Ptr<cv::aruco::Dictionary> aruco =
      ArucoDictionaryByName(dictionary);  // throws for unknown names
  if (count > aruco->bytesList.rows) {
    throw OptionError(
        "survey.markers.count", count,
        "<= " + std::to_string(aruco->bytesList.rows) + " (the ids of " + dictionary + ")");
  }
}

namespace {

// world_from_face of a plate centred over (x, y): face z along the
// seabed's downward normal (the print, facing -z, looks up), face x along
// world x as far as the tilt allows -- the frame of a camera looking down
// with x along the track, so the print is seen as printed.
Rigid3d PlateFrame(const SeabedObject& seabed, double x, double y, double half_extent) {
  Eigen::Vector2d gradient;
  const double z = seabed.Height(x, y, &gradient);
  const Eigen::Vector3d up = Eigen::Vector3d(-gradient.x(), -gradient.y(), 1.0).normalized();
  const Eigen::Vector3d face_z = -up;
  const Eigen::Vector3d face_x = (Eigen::Vector3d::UnitX() - up * up.x()).normalized();
  Eigen::Matrix3d rotation;
  rotation << face_x, face_z.cross(face_x), face_z;
  // Lifted clear of the relief under the plate (its corners and edges'
  // middles; the relief's wavelength is metres, the plate decimetres).
  double lift = 0;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      const Eigen::Vector3d offset =
          rotation * Eigen::Vector3d(0.5 * i * half_extent, 0.5 * j * half_extent, 0);
      const Eigen::Vector3d p = Eigen::Vector3d(x, y, z) + offset;
      lift = std::max(lift, (seabed.Height(p.x(), p.y()) - p.z()) / up.z());
    }
  }
  return Rigid3d(Eigen::Quaterniond(rotation), Eigen::Vector3d(x, y, z) + (lift + 0.002) * up);
}

}  // namespace

SeabedMarkers PlaceSeabedMarkers(const SeabedMarkerOptions& options, const SeabedObject& seabed,
                                 const Eigen::Vector4d& area, const PrintLevels& levels) {
  options.Check();
  SeabedMarkers result;
  if (options.count == 0) return result;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = ArucoDictionaryByName(options.dictionary);
  const double h = 0.5 * options.side_m, half_extent = h + 0.25 * options.side_m;
  // TL, TR, BR, BL of the print in the face frame (y down the print): the
  // print faces -z (target_builder's rule).
  const std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(-h, -h), Eigen::Vector2d(h, -h),
                                                  Eigen::Vector2d(h, h), Eigen::Vector2d(-h, h)};
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options.count))));
  std::vector<Face> faces;
  for (int id = 0; id < options.count; ++id) {
    const double x = area[0] + options.spacing_m * (1 + id % columns);
    const double y = area[2] + options.spacing_m * (1 + id / columns);
    PlacedMarker print;
    print.id = id;
    print.corners = corners;
    print.modules = ArucoMarkerModules(*dictionary, id, &print.modules_per_side);
    const Eigen::Vector4d extent(-half_extent, half_extent, -half_extent, half_extent);
    auto texture =
        std::make_shared<MarkerBoardTexture>(std::vector<PlacedMarker>{print}, extent, levels);
    const Rigid3d world_from_face = PlateFrame(seabed, x, y, half_extent);
    faces.push_back({texture, world_from_face, -1.0});
    SeabedMarker marker;
    marker.id = id;
    for (int k = 0; k < 4; ++k)
      marker.corners[k] = world_from_face * Eigen::Vector3d(corners[k].x(), corners[k].y(), 0);
    result.markers.push_back(marker);
  }
  result.object = std::make_unique<FacesObject>(std::move(faces), static_cast<float>(levels.back));
  return result;
}

}  // namespace portcal
