// COLMAP 3.8 binary model files (little-endian, as COLMAP writes them on the
// platforms it supports).
#include <fstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

class BinaryReader {
 public:
  explicit BinaryReader(const fs::path& path)
      : path_(path), file_(path, std::ios::binary) {
    if (!file_) throw InputError(path.string() + ": cannot open");
  }

  template <typename T>
  T Read(const char* what) {
    T value;
    file_.read(reinterpret_cast<char*>(&value), sizeof(T));
    if (!file_) {
      throw InputError(path_.string() + ": truncated file while reading " + what);
    }
    return value;
  }

  double ReadFinite(const char* what) {
    const double value = Read<double>(what);
    if (!std::isfinite(value)) {
      throw InputError(path_.string() + ": non-finite " + what);
    }
    return value;
  }

  std::string ReadName() {
    std::string name;
    char c;
    while (true) {
      c = Read<char>("image name");
      if (c == '\0') break;
      name.push_back(c);
    }
    return name;
  }

  // Guards counts before allocating: each item takes at least `item_bytes`.
  uint64_t ReadCount(const char* what, uint64_t item_bytes) {
    const uint64_t count = Read<uint64_t>(what);
    const auto position = file_.tellg();
    file_.seekg(0, std::ios::end);
    const auto end = file_.tellg();
    file_.seekg(position);
    if (item_bytes > 0 &&
        count > static_cast<uint64_t>(end - position) / item_bytes) {
      throw InputError(path_.string() + ": implausible " + what + " " +
                       std::to_string(count) + " (file too short)");
    }
    return count;
  }

  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  std::ifstream file_;
};

template <typename T>
void Write(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace

std::map<camera_t, Camera> ReadCamerasBinary(const fs::path& path) {
  BinaryReader reader(path);
  std::map<camera_t, Camera> cameras;
  const uint64_t num_cameras = reader.ReadCount("number of cameras", 24);
  for (uint64_t i = 0; i < num_cameras; ++i) {
    Camera camera;
    camera.camera_id = reader.Read<uint32_t>("camera id");
    camera.model_id = reader.Read<int32_t>("camera model");
    const std::string where =
        path.string() + ": camera " + std::to_string(camera.camera_id);
    if (!ExistsCameraModelWithId(camera.model_id)) {
      throw InputError(where + ": unknown camera model id " +
                       std::to_string(camera.model_id));
    }
    camera.width = reader.Read<uint64_t>("width");
    camera.height = reader.Read<uint64_t>("height");
    camera.params.resize(CameraModelNumParams(camera.model_id));
    for (double& param : camera.params) param = reader.ReadFinite("camera parameter");
    camera.Validate(where);
    cameras[camera.camera_id] = camera;
  }
  return cameras;
}

std::map<image_t, Image> ReadImagesBinary(const fs::path& path) {
  BinaryReader reader(path);
  std::map<image_t, Image> images;
  const uint64_t num_images = reader.ReadCount("number of images", 64);
  for (uint64_t i = 0; i < num_images; ++i) {
    Image image;
    image.image_id = reader.Read<uint32_t>("image id");
    Eigen::Vector4d wxyz;
    for (int k = 0; k < 4; ++k) wxyz[k] = reader.ReadFinite("quaternion");
    image.cam_from_world.rotation = QuaternionFromWxyz(wxyz).normalized();
    for (int k = 0; k < 3; ++k) {
      image.cam_from_world.translation[k] = reader.ReadFinite("translation");
    }
    image.camera_id = reader.Read<uint32_t>("camera id");
    image.name = reader.ReadName();
    const uint64_t num_points2D = reader.ReadCount("number of 2D points", 24);
    image.points2D.resize(num_points2D);
    for (Point2D& point2D : image.points2D) {
      point2D.xy.x() = reader.ReadFinite("2D point x");
      point2D.xy.y() = reader.ReadFinite("2D point y");
      point2D.point3D_id = reader.Read<uint64_t>("3D point id");
    }
    images[image.image_id] = std::move(image);
  }
  return images;
}

std::map<point3D_t, Point3D> ReadPoints3DBinary(const fs::path& path) {
  BinaryReader reader(path);
  std::map<point3D_t, Point3D> points3D;
  const uint64_t num_points = reader.ReadCount("number of 3D points", 51);
  for (uint64_t i = 0; i < num_points; ++i) {
    const point3D_t id = reader.Read<uint64_t>("3D point id");
    Point3D point;
    for (int k = 0; k < 3; ++k) point.xyz[k] = reader.ReadFinite("3D point");
    for (int k = 0; k < 3; ++k) point.color[k] = reader.Read<uint8_t>("color");
    point.error = reader.Read<double>("error");
    const uint64_t track_length = reader.ReadCount("track length", 8);
    point.track.resize(track_length);
    for (TrackElement& element : point.track) {
      element.image_id = reader.Read<uint32_t>("track image id");
      element.point2D_idx = reader.Read<uint32_t>("track point index");
    }
    points3D[id] = std::move(point);
  }
  return points3D;
}

void WriteCamerasBinary(const SparseModel& model, std::ostream& out) {
  Write<uint64_t>(out, model.cameras.size());
  for (const auto& [camera_id, camera] : model.cameras) {
    Write<uint32_t>(out, camera_id);
    Write<int32_t>(out, camera.model_id);
    Write<uint64_t>(out, camera.width);
    Write<uint64_t>(out, camera.height);
    for (const double param : camera.params) Write<double>(out, param);
  }
}

void WriteImagesBinary(const SparseModel& model, std::ostream& out) {
  Write<uint64_t>(out, model.images.size());
  for (const auto& [image_id, image] : model.images) {
    Write<uint32_t>(out, image_id);
    const Eigen::Vector4d wxyz =
        QuaternionToWxyz(image.cam_from_world.rotation.normalized());
    for (int k = 0; k < 4; ++k) Write<double>(out, wxyz[k]);
    for (int k = 0; k < 3; ++k) {
      Write<double>(out, image.cam_from_world.translation[k]);
    }
    Write<uint32_t>(out, image.camera_id);
    out.write(image.name.c_str(), image.name.size() + 1);
    Write<uint64_t>(out, image.points2D.size());
    for (const Point2D& point2D : image.points2D) {
      Write<double>(out, point2D.xy.x());
      Write<double>(out, point2D.xy.y());
      Write<uint64_t>(out, point2D.point3D_id);
    }
  }
}

void WritePoints3DBinary(const SparseModel& model, std::ostream& out) {
  Write<uint64_t>(out, model.points3D.size());
  for (const auto& [id, point] : model.points3D) {
    Write<uint64_t>(out, id);
    for (int k = 0; k < 3; ++k) Write<double>(out, point.xyz[k]);
    for (int k = 0; k < 3; ++k) Write<uint8_t>(out, point.color[k]);
    Write<double>(out, point.error);
    Write<uint64_t>(out, point.track.size());
    for (const TrackElement& element : point.track) {
      Write<uint32_t>(out, element.image_id);
      Write<uint32_t>(out, element.point2D_idx);
    }
  }
}

}  // namespace portcal
