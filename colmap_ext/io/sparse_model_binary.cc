// COLMAP 3.8 binary model files (little-endian, as COLMAP writes them on the
// platforms it supports).
#include <fstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/binary_reader.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

namespace fs = std::filesystem;

namespace portcal {

std::map<camera_t, Camera> ReadCamerasBinary(const fs::path& path) {
  BinaryReader reader(path);
  std::map<camera_t, Camera> cameras;
  const uint64_t num_cameras = reader.ReadCount("number of cameras", 24);
  for (uint64_t i = 0; i < num_cameras; ++i) {
    Camera camera;
    camera.camera_id = reader.Read<uint32_t>("camera id");
    camera.model_id = reader.Read<int32_t>("camera model");
    const std::string where = path.string() + ": camera " + std::to_string(camera.camera_id);
    if (!ExistsCameraModelWithId(camera.model_id)) {
      throw InputError(where + ": unknown camera model id " + std::to_string(camera.model_id));
    }
    camera.width = reader.Read<uint64_t>("width");
    camera.height = reader.Read<uint64_t>("height");
    camera.params.resize(CameraModelNumParams(camera.model_id));
    for (double& param : camera.params) param = reader.ReadFinite("camera parameter");
    camera.Validate(where);
    if (!cameras.emplace(camera.camera_id, camera).second)
      throw InputError(where + ": a second camera of this id");
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
    const image_t image_id = image.image_id;
    if (!images.emplace(image_id, std::move(image)).second) {
      throw InputError(path.string() + ": image " + std::to_string(image_id) +
                       ": a second image of this id");
    }
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
    if (!points3D.emplace(id, std::move(point)).second) {
      throw InputError(path.string() + ": 3D point " + std::to_string(id) +
                       ": a second point of this id");
    }
  }
  return points3D;
}

void WriteCamerasBinary(const SparseModel& model, std::ostream& out) {
  WriteLittleEndian<uint64_t>(out, model.cameras.size());
  for (const auto& [camera_id, camera] : model.cameras) {
    WriteLittleEndian<uint32_t>(out, camera_id);
    WriteLittleEndian<int32_t>(out, camera.model_id);
    WriteLittleEndian<uint64_t>(out, camera.width);
    WriteLittleEndian<uint64_t>(out, camera.height);
    for (const double param : camera.params) WriteLittleEndian<double>(out, param);
  }
}

void WriteImagesBinary(const SparseModel& model, std::ostream& out) {
  WriteLittleEndian<uint64_t>(out, model.images.size());
  for (const auto& [image_id, image] : model.images) {
    WriteLittleEndian<uint32_t>(out, image_id);
    const Eigen::Vector4d wxyz = QuaternionToWxyz(image.cam_from_world.rotation.normalized());
    for (int k = 0; k < 4; ++k) WriteLittleEndian<double>(out, wxyz[k]);
    for (int k = 0; k < 3; ++k) {
      WriteLittleEndian<double>(out, image.cam_from_world.translation[k]);
    }
    WriteLittleEndian<uint32_t>(out, image.camera_id);
    out.write(image.name.c_str(), image.name.size() + 1);
    WriteLittleEndian<uint64_t>(out, image.points2D.size());
    for (const Point2D& point2D : image.points2D) {
      WriteLittleEndian<double>(out, point2D.xy.x());
      WriteLittleEndian<double>(out, point2D.xy.y());
      WriteLittleEndian<uint64_t>(out, point2D.point3D_id);
    }
  }
}

void WritePoints3DBinary(const SparseModel& model, std::ostream& out) {
  WriteLittleEndian<uint64_t>(out, model.points3D.size());
  for (const auto& [id, point] : model.points3D) {
    WriteLittleEndian<uint64_t>(out, id);
    for (int k = 0; k < 3; ++k) WriteLittleEndian<double>(out, point.xyz[k]);
    for (int k = 0; k < 3; ++k) WriteLittleEndian<uint8_t>(out, point.color[k]);
    WriteLittleEndian<double>(out, point.error);
    WriteLittleEndian<uint64_t>(out, point.track.size());
    for (const TrackElement& element : point.track) {
      WriteLittleEndian<uint32_t>(out, element.image_id);
      WriteLittleEndian<uint32_t>(out, element.point2D_idx);
    }
  }
}

}  // namespace portcal
