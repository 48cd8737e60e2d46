// COLMAP 3.8 text model files. Numbers are written with 17 significant
// digits, as COLMAP writes them, so text round trips lose nothing.
#include <fstream>
#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::ifstream OpenText(const fs::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open");
  return file;
}

bool IsDataLine(const std::string& line) {
  const std::string trimmed = Trim(line);
  return !trimmed.empty() && trimmed[0] != '#';
}

std::string Where(const fs::path& path, int line_number) {
  return path.string() + ":" + std::to_string(line_number);
}

}  // namespace

std::map<camera_t, Camera> ReadCamerasText(const fs::path& path) {
  // The refractive fork's format is a superset; a stock file has no housing.
  std::map<camera_t, Camera> cameras;
  std::map<camera_t, Housing> housings;
  ImportRefractiveCamerasText(path, &cameras, &housings);
  if (!housings.empty()) {
    throw InputError(path.string() + ": camera " + std::to_string(housings.begin()->first) +
                     " carries a housing (refractive fork format); read the model with "
                     "ReadSparseModel or convert it with portcal model_converter");
  }
  return cameras;
}

std::map<image_t, Image> ReadImagesText(const fs::path& path) {
  std::ifstream file = OpenText(path);
  std::map<image_t, Image> images;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    if (!IsDataLine(line)) continue;
    const std::string where = Where(path, line_number);
    // NAME may contain spaces: it is everything after the 9th token.
    std::istringstream in(line);
    std::vector<std::string> head(9);
    for (std::string& token : head) {
      if (!(in >> token)) {
        throw InputError(where + ": expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
      }
    }
    std::string name;
    std::getline(in >> std::ws, name);
    name = Trim(name);
    if (name.empty()) throw InputError(where + ": image without a name");
    Image image;
    image.image_id =
        static_cast<image_t>(ParseInteger(head[0], where + " image id", 0, 2147483646));
    const Eigen::Vector4d wxyz(ParseDouble(head[1], where), ParseDouble(head[2], where),
                               ParseDouble(head[3], where), ParseDouble(head[4], where));
    image.cam_from_world.rotation = QuaternionFromWxyz(wxyz).normalized();
    image.cam_from_world.translation = {ParseDouble(head[5], where), ParseDouble(head[6], where),
                                        ParseDouble(head[7], where)};
    image.camera_id =
        static_cast<camera_t>(ParseInteger(head[8], where + " camera id", 0, 0xFFFFFFFELL));
    image.name = name;

    // The second line holds the 2D points and may be empty.
    std::string points_line;
    ++line_number;
    std::getline(file, points_line);
    const std::vector<std::string> tokens = SplitTokens(points_line, " \t\r");
    if (tokens.size() % 3 != 0) {
      throw InputError(Where(path, line_number) + ": expected triples X Y POINT3D_ID");
    }
    for (size_t i = 0; i < tokens.size(); i += 3) {
      Point2D point2D;
      point2D.xy = {ParseDouble(tokens[i], Where(path, line_number)),
                    ParseDouble(tokens[i + 1], Where(path, line_number))};
      const long long id = ParseInteger(tokens[i + 2], Where(path, line_number), -1, (1LL << 62));
      point2D.point3D_id = id < 0 ? kInvalidPoint3DId : static_cast<point3D_t>(id);
      image.points2D.push_back(point2D);
    }
    if (!images.emplace(image.image_id, std::move(image)).second) {
      throw InputError(where + ": duplicate image id " + head[0]);
    }
  }
  return images;
}

std::map<point3D_t, Point3D> ReadPoints3DText(const fs::path& path) {
  std::ifstream file = OpenText(path);
  std::map<point3D_t, Point3D> points3D;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    if (!IsDataLine(line)) continue;
    const std::string where = Where(path, line_number);
    const std::vector<std::string> tokens = SplitTokens(line, " \t\r");
    if (tokens.size() < 8 || (tokens.size() - 8) % 2 != 0) {
      throw InputError(where + ": expected POINT3D_ID X Y Z R G B ERROR TRACK[] pairs");
    }
    const point3D_t id = ParseInteger(tokens[0], where + " point id", 0, (1LL << 62));
    Point3D point;
    point.xyz = {ParseDouble(tokens[1], where), ParseDouble(tokens[2], where),
                 ParseDouble(tokens[3], where)};
    for (int c = 0; c < 3; ++c) {
      point.color[c] = static_cast<uint8_t>(ParseInteger(tokens[4 + c], where + " color", 0, 255));
    }
    point.error = ParseDouble(tokens[7], where);
    for (size_t i = 8; i < tokens.size(); i += 2) {
      TrackElement element;
      element.image_id =
          static_cast<image_t>(ParseInteger(tokens[i], where + " track image id", 0, 2147483646));
      element.point2D_idx = static_cast<point2D_t>(
          ParseInteger(tokens[i + 1], where + " track point index", 0, 0xFFFFFFFFLL));
      point.track.push_back(element);
    }
    if (!points3D.emplace(id, std::move(point)).second) {
      throw InputError(where + ": duplicate 3D point id " + tokens[0]);
    }
  }
  return points3D;
}

void WriteCamerasText(const SparseModel& model, std::ostream& out) {
  out.precision(17);
  out << "# Camera list with one line of data per camera:\n"
      << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      << "# Number of cameras: " << model.cameras.size() << "\n";
  for (const auto& [camera_id, camera] : model.cameras) {
    out << camera_id << " " << camera.ModelName() << " " << camera.width << " " << camera.height;
    for (const double param : camera.params) out << " " << param;
    out << "\n";
  }
}

void WriteImagesText(const SparseModel& model, std::ostream& out) {
  size_t num_observations = 0;
  for (const auto& [image_id, image] : model.images) {
    for (const Point2D& point2D : image.points2D) {
      num_observations += point2D.point3D_id != kInvalidPoint3DId;
    }
  }
  const double mean_observations =
      model.images.empty()
          ? 0.0
          : static_cast<double>(num_observations) / static_cast<double>(model.images.size());
  out.precision(17);
  out << "# Image list with two lines of data per image:\n"
      << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      << "# Number of images: " << model.images.size()
      << ", mean observations per image: " << mean_observations << "\n";
  for (const auto& [image_id, image] : model.images) {
    const Eigen::Vector4d wxyz = QuaternionToWxyz(image.cam_from_world.rotation.normalized());
    const Eigen::Vector3d& t = image.cam_from_world.translation;
    out << image_id << " " << wxyz[0] << " " << wxyz[1] << " " << wxyz[2] << " " << wxyz[3] << " "
        << t[0] << " " << t[1] << " " << t[2] << " " << image.camera_id << " " << image.name
        << "\n";
    std::ostringstream points;
    points.precision(17);
    for (const Point2D& point2D : image.points2D) {
      points << point2D.xy.x() << " " << point2D.xy.y() << " ";
      if (point2D.point3D_id == kInvalidPoint3DId) {
        points << -1 << " ";
      } else {
        points << point2D.point3D_id << " ";
      }
    }
    std::string line = points.str();
    if (!line.empty()) line.pop_back();
    out << line << "\n";
  }
}

void WritePoints3DText(const SparseModel& model, std::ostream& out) {
  size_t track_sum = 0;
  for (const auto& [id, point] : model.points3D) track_sum += point.track.size();
  const double mean_track = model.points3D.empty() ? 0.0
                                                   : static_cast<double>(track_sum) /
                                                         static_cast<double>(model.points3D.size());
  out.precision(17);
  out << "# 3D point list with one line of data per point:\n"
      << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, "
         "POINT2D_IDX)\n"
      << "# Number of points: " << model.points3D.size() << ", mean track length: " << mean_track
      << "\n";
  for (const auto& [id, point] : model.points3D) {
    out << id << " " << point.xyz.x() << " " << point.xyz.y() << " " << point.xyz.z() << " "
        << static_cast<int>(point.color[0]) << " " << static_cast<int>(point.color[1]) << " "
        << static_cast<int>(point.color[2]) << " " << point.error;
    for (const TrackElement& element : point.track) {
      out << " " << element.image_id << " " << element.point2D_idx;
    }
    out << "\n";
  }
}

}  // namespace portcal
