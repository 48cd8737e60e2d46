#include "pipelines/synthetic/target_builder.h"

#include <opencv2/aruco/charuco.hpp>
#include <random>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "pipelines/markers/aruco.h"

namespace portcal {

void TargetOptions::Check() const {
  if (type != "chessboard" && type != "aruco_grid" && type != "charuco" && type != "target3d") {
    throw OptionError("target.type", type, "chessboard, aruco_grid, charuco or target3d");
  }
  if (type == "chessboard" && (cols < 2 || rows < 2)) {
    throw OptionError("target.cols/rows", std::to_string(cols) + "x" + std::to_string(rows),
                      ">= 2 inner corners each");
  }
  if (type == "charuco" && (squares_x < 3 || squares_y < 3)) {
    throw OptionError("target.squares_x/squares_y", squares_x, ">= 3 each");
  }
  if (!(square_size_m > 0)) throw OptionError("target.square_size", square_size_m, "> 0 m");
  if (!(margin_m >= 0)) throw OptionError("target.margin", margin_m, ">= 0 m");
  if (type == "aruco_grid" && (markers_x < 1 || markers_y < 1)) {
    throw OptionError("target.markers_x/markers_y", markers_x, ">= 1 each");
  }
  if (!(marker_size_m > 0)) throw OptionError("target.marker_size", marker_size_m, "> 0 m");
  if (type == "charuco" && !(marker_size_m < square_size_m)) {
    throw OptionError("target.marker_size", marker_size_m, "< square_size");
  }
  if (!(marker_separation_m >= 0)) {
    throw OptionError("target.marker_separation", marker_separation_m, ">= 0 m");
  }
  if (type == "target3d") {
    if (num_faces < 2 || num_faces > 3) throw OptionError("target.num_faces", num_faces, "2 or 3");
    if (!(fold_angle_deg >= 60 && fold_angle_deg <= 180)) {
      throw OptionError("target.fold_angle_deg", fold_angle_deg, "[60, 180]");
    }
    if (!(face_width_m > 0 && face_height_m > 0)) {
      throw OptionError("target.face_width/face_height", face_width_m, "> 0 m");
    }
    if (!marker_ids.empty() && static_cast<int>(marker_ids.size()) != num_faces) {
      throw OptionError("target.marker_ids", std::to_string(marker_ids.size()) + " ids",
                        "one per face");
    }
    if (!(dots.r_min_m > 0 && dots.r_max_m >= dots.r_min_m)) {
      throw OptionError("target.dots.r_min/r_max", dots.r_min_m, "0 < r_min <= r_max");
    }
    if (!(dots.coverage > 0 && dots.coverage <= 0.8)) {
      throw OptionError("target.dots.coverage", dots.coverage, "(0, 0.8]");
    }
  }
  ArucoDictionaryByName(dictionary);  // throws for unknown names
}

namespace {

PlacedMarker MakeMarker(const cv::aruco::Dictionary& dictionary, int id,
                        const std::array<Eigen::Vector2d, 4>& corners) {
  PlacedMarker marker;
  marker.id = id;
  marker.corners = corners;
  marker.modules = ArucoMarkerModules(dictionary, id, &marker.modules_per_side);
  return marker;
}

Eigen::Vector3d Lift(const Eigen::Vector2d& p) { return {p.x(), p.y(), 0.0}; }

void AddOutline(const Eigen::Vector4d& extent, BuiltTarget* target) {
  for (const Eigen::Vector2d& p :
       {Eigen::Vector2d(extent[0], extent[2]), Eigen::Vector2d(extent[1], extent[2]),
        Eigen::Vector2d(extent[1], extent[3]), Eigen::Vector2d(extent[0], extent[3])}) {
    target->outline_points.push_back(Lift(p));
  }
  target->center =
      Lift(Eigen::Vector2d(0.5 * (extent[0] + extent[1]), 0.5 * (extent[2] + extent[3])));
}

BuiltTarget BuildChessboard(const TargetOptions& o, const PrintLevels& levels) {
  BuiltTarget target;
  auto texture =
      std::make_shared<ChessboardTexture>(o.cols, o.rows, o.square_size_m, o.margin_m, levels);
  TargetDescription& d = target.description;
  d.type = "chessboard";
  d.inner_corners_cols = o.cols;
  d.inner_corners_rows = o.rows;
  d.square_size = o.square_size_m;
  d.margin = o.margin_m;
  for (int r = 0; r < o.rows; ++r) {
    for (int c = 0; c < o.cols; ++c)
      d.corners_3d.emplace_back(c * o.square_size_m, r * o.square_size_m, 0);
  }
  AddOutline(texture->Extent(), &target);
  target.marker_points = target.outline_points;
  target.object = std::make_unique<FacesObject>(std::vector<Face>{{texture, Rigid3d(), -1.0}},
                                                static_cast<float>(levels.back));
  return target;
}

// Markers of an OpenCV board (its objPoints: TL, TR, BR, BL of each marker).
BuiltTarget BuildMarkerBoard(const TargetOptions& o, const PrintLevels& levels,
                             const cv::aruco::Board& board, const cv::aruco::Dictionary& dictionary,
                             bool charuco) {
  BuiltTarget target;
  TargetDescription& d = target.description;
  d.type = o.type;
  d.aruco_dictionary = o.dictionary;
  d.marker_size = o.marker_size_m;
  d.margin = o.margin_m;
  std::vector<PlacedMarker> markers;
  Eigen::Vector4d extent(1e300, -1e300, 1e300, -1e300);
  for (size_t i = 0; i < board.objPoints.size(); ++i) {
    std::array<Eigen::Vector2d, 4> corners;
    TargetMarker marker;
    marker.id = board.ids[i];
    for (int k = 0; k < 4; ++k) {
      const cv::Point3f& p = board.objPoints[i][k];
      corners[k] = {p.x, p.y};
      marker.corners[k] = {p.x, p.y, p.z};
      extent = Eigen::Vector4d(std::min(extent[0], double(p.x)), std::max(extent[1], double(p.x)),
                               std::min(extent[2], double(p.y)), std::max(extent[3], double(p.y)));
      target.marker_points.push_back(marker.corners[k]);
    }
    d.markers.push_back(marker);
    markers.push_back(MakeMarker(dictionary, marker.id, corners));
  }
  if (charuco) {
    extent = Eigen::Vector4d(0, o.squares_x * o.square_size_m, 0, o.squares_y * o.square_size_m);
  }
  extent += Eigen::Vector4d(-o.margin_m, o.margin_m, -o.margin_m, o.margin_m);
  // The print faces away from (TR - TL) x (BL - TL) (cv::aruco's clockwise
  // corner order as seen in the image).
  const Eigen::Vector3d away = (d.markers[0].corners[1] - d.markers[0].corners[0])
                                   .cross(d.markers[0].corners[3] - d.markers[0].corners[0]);
  const double front_z = away.z() > 0 ? -1.0 : 1.0;
  target.front_normal = Eigen::Vector3d(0, 0, front_z);
  auto texture = std::make_shared<MarkerBoardTexture>(std::move(markers), extent, levels);
  if (charuco) texture->SetSquares(o.squares_x, o.squares_y, o.square_size_m);
  AddOutline(extent, &target);
  target.object = std::make_unique<FacesObject>(std::vector<Face>{{texture, Rigid3d(), front_z}},
                                                static_cast<float>(levels.back));
  return target;
}

std::vector<Dot> RandomDots(const TargetOptions& o, int face, const Eigen::Vector4d& extent,
                            const Eigen::Vector4d& keep_out) {
  std::mt19937_64 rng(o.dots.seed * 1000003ULL + face);
  std::uniform_real_distribution<double> unit(0, 1);
  const DotsOptions& p = o.dots;
  const double free_area = (extent[1] - extent[0] - 2 * p.edge_margin_m) *
                               (extent[3] - extent[2] - 2 * p.edge_margin_m) -
                           (keep_out[1] - keep_out[0]) * (keep_out[3] - keep_out[2]);
  std::vector<Dot> dots;
  double covered = 0;
  for (int attempt = 0; attempt < 200000 && covered < p.coverage * free_area; ++attempt) {
    Dot dot;
    dot.radius = p.r_min_m + unit(rng) * (p.r_max_m - p.r_min_m);
    const double m = p.edge_margin_m + dot.radius;
    dot.x = extent[0] + m + unit(rng) * (extent[1] - extent[0] - 2 * m);
    dot.y = extent[2] + m + unit(rng) * (extent[3] - extent[2] - 2 * m);
    dot.gray = static_cast<float>(p.gray_min + unit(rng) * (p.gray_max - p.gray_min));
    if (dot.x + dot.radius > keep_out[0] && dot.x - dot.radius < keep_out[1] &&
        dot.y + dot.radius > keep_out[2] && dot.y - dot.radius < keep_out[3]) {
      continue;
    }
    bool overlaps = false;
    for (const Dot& other : dots) {
      const double gap = dot.radius + other.radius + 0.5 * p.r_min_m;
      if ((dot.x - other.x) * (dot.x - other.x) + (dot.y - other.y) * (dot.y - other.y) <
          gap * gap) {
        overlaps = true;
        break;
      }
    }
    if (overlaps) continue;
    dots.push_back(dot);
    covered += M_PI * dot.radius * dot.radius;
  }
  return dots;
}

BuiltTarget BuildTarget3d(const TargetOptions& o, const PrintLevels& levels,
                          const cv::aruco::Dictionary& dictionary) {
  BuiltTarget target;
  TargetDescription& d = target.description;
  d.type = "target3d";
  d.layout = o.num_faces == 2 ? "fold" : "tent";
  d.fold_angle_deg = o.fold_angle_deg;
  d.face_width = o.face_width_m;
  d.face_height = o.face_height_m;
  d.aruco_dictionary = o.dictionary;
  d.marker_size = o.target3d_marker_size_m;
  d.dots_file = "target_dots.csv";
  const double w = o.face_width_m, h = o.face_height_m;
  const double tilt = (180.0 - o.fold_angle_deg) * M_PI / 180.0;
  std::vector<Rigid3d> target_from_face;
  const auto about_y = [](double angle) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
  };
  if (o.num_faces == 2) {
    // A fold with its ridge towards the viewer: each face turned by half the
    // fold's complement.
    const double a = 0.5 * tilt;
    target_from_face.emplace_back(about_y(a), Eigen::Vector3d(-0.5 * w * std::cos(a), 0, 0));
    target_from_face.emplace_back(about_y(-a), Eigen::Vector3d(0.5 * w * std::cos(a), 0, 0));
  } else {
    // A tent: a middle face square to the viewer, two wings folded back.
    target_from_face.emplace_back(
        about_y(tilt),
        Eigen::Vector3d(-0.5 * w - 0.5 * w * std::cos(tilt), 0, 0.5 * w * std::sin(tilt)));
    target_from_face.emplace_back(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
    target_from_face.emplace_back(
        about_y(-tilt),
        Eigen::Vector3d(0.5 * w + 0.5 * w * std::cos(tilt), 0, 0.5 * w * std::sin(tilt)));
  }
  const Eigen::Vector4d extent(-0.5 * w, 0.5 * w, -0.5 * h, 0.5 * h);
  std::vector<Face> faces;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int f = 0; f < o.num_faces; ++f) {
    const int id = o.marker_ids.empty() ? f : o.marker_ids[f];
    const double s = o.target3d_marker_size_m;
    std::array<Eigen::Vector2d, 4> corners = {
        Eigen::Vector2d(-s / 2, -s / 2), Eigen::Vector2d(s / 2, -s / 2),
        Eigen::Vector2d(s / 2, s / 2), Eigen::Vector2d(-s / 2, s / 2)};
    PlacedMarker marker = MakeMarker(dictionary, id, corners);
    const double module = s / marker.modules_per_side;
    const double quiet = o.quiet_zone_modules * module;
    const Eigen::Vector4d keep_out(-s / 2 - quiet, s / 2 + quiet, -s / 2 - quiet, s / 2 + quiet);
    std::vector<Dot> dots = RandomDots(o, f, extent, keep_out);
    TargetFace face;
    face.name = "face" + std::to_string(f);
    face.target_from_face = target_from_face[f];
    face.extent_x = {extent[0], extent[1]};
    face.extent_y = {extent[2], extent[3]};
    face.marker_id = id;
    face.marker_side = s;
    face.marker_module = module;
    face.quiet_zone = quiet;
    face.num_dots = static_cast<int>(dots.size());
    d.faces.push_back(face);
    TargetMarker target_marker;
    target_marker.id = id;
    for (int k = 0; k < 4; ++k) {
      target_marker.corners[k] = target_from_face[f] * Lift(corners[k]);
      target.marker_points.push_back(target_marker.corners[k]);
    }
    d.markers.push_back(target_marker);
    for (const Eigen::Vector2d& p :
         {Eigen::Vector2d(extent[0], extent[2]), Eigen::Vector2d(extent[1], extent[2]),
          Eigen::Vector2d(extent[1], extent[3]), Eigen::Vector2d(extent[0], extent[3])}) {
      target.outline_points.push_back(target_from_face[f] * Lift(p));
      centroid += target.outline_points.back();
    }
    target.dots.push_back(dots);
    faces.push_back(
        {std::make_shared<DotsFaceTexture>(std::move(dots), marker, quiet, extent, levels),
         target_from_face[f], -1.0});
  }
  target.center = centroid / static_cast<double>(target.outline_points.size());
  target.object = std::make_unique<FacesObject>(std::move(faces), static_cast<float>(levels.back));
  return target;
}

}  // namespace

BuiltTarget BuildTarget(const TargetOptions& options, const PrintLevels& levels) {
  options.Check();
  const cv::Ptr<cv::aruco::Dictionary> dictionary = ArucoDictionaryByName(options.dictionary);
  if (options.type == "chessboard") return BuildChessboard(options, levels);
  if (options.type == "aruco_grid") {
    const cv::Ptr<cv::aruco::GridBoard> board = cv::aruco::GridBoard::create(
        options.markers_x, options.markers_y, static_cast<float>(options.marker_size_m),
        static_cast<float>(options.marker_separation_m), dictionary, options.first_marker);
    BuiltTarget target = BuildMarkerBoard(options, levels, *board, *dictionary, false);
    target.description.markers_x = options.markers_x;
    target.description.markers_y = options.markers_y;
    target.description.marker_separation = options.marker_separation_m;
    return target;
  }
  if (options.type == "charuco") {
    const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
        options.squares_x, options.squares_y, static_cast<float>(options.square_size_m),
        static_cast<float>(options.marker_size_m), dictionary);
    BuiltTarget target = BuildMarkerBoard(options, levels, *board, *dictionary, true);
    TargetDescription& d = target.description;
    d.inner_corners_cols = options.squares_x - 1;
    d.inner_corners_rows = options.squares_y - 1;
    d.square_size = options.square_size_m;
    for (const cv::Point3f& p : board->chessboardCorners) d.corners_3d.emplace_back(p.x, p.y, p.z);
    return target;
  }
  return BuildTarget3d(options, levels, *dictionary);
}

std::string DotsCsv(const std::vector<std::vector<Dot>>& dots) {
  std::ostringstream out;
  out.precision(9);
  out << "# face,x,y,radius,gray  (face frame, metres; gray level 0-255)\n";
  for (size_t f = 0; f < dots.size(); ++f) {
    for (const Dot& d : dots[f]) {
      out << f << "," << d.x << "," << d.y << "," << d.radius << "," << d.gray << "\n";
    }
  }
  return out.str();
}

}  // namespace portcal
