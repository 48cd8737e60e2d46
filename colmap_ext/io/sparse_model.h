// COLMAP 3.8 sparse models (cameras, images, points3D in .bin or .txt) plus
// portcal's sidecar housings.txt, which stock COLMAP ignores.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/types.h"

namespace portcal {

constexpr point3D_t kInvalidPoint3DId = static_cast<point3D_t>(-1);

struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  point3D_t point3D_id = kInvalidPoint3DId;
};

struct Image {
  image_t image_id = 0;
  std::string name;
  camera_t camera_id = kInvalidCameraId;
  Rigid3d cam_from_world;
  std::vector<Point2D> points2D;
};

struct TrackElement {
  image_t image_id = 0;
  point2D_t point2D_idx = 0;
};

struct Point3D {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Matrix<uint8_t, 3, 1> color = Eigen::Matrix<uint8_t, 3, 1>::Zero();
  double error = -1.0;
  std::vector<TrackElement> track;
};

// COLMAP 3.12 on: sensors (cameras, IMUs) grouped into rigs, and frames
// (one rig's pose at one time) holding the data each sensor took then.
constexpr int kModelSensorCamera = 0;  // COLMAP's SensorType: INVALID -1, CAMERA 0, IMU 1

struct ModelSensor {
  int type = kModelSensorCamera;
  uint32_t id = 0;
  bool operator==(const ModelSensor& other) const { return type == other.type && id == other.id; }
};

struct ModelRig {
  std::optional<ModelSensor> ref_sensor;  // none: a rig without sensors
  // The other sensors and, where known, sensor_from_rig.
  std::vector<std::pair<ModelSensor, std::optional<Rigid3d>>> sensors;
};

struct ModelFrame {
  uint32_t rig_id = 0;
  Rigid3d rig_from_world;
  std::vector<std::pair<ModelSensor, uint64_t>>
      data;  // (sensor, data id: an image id for a camera)
};

struct SparseModel {
  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;  // registered images
  std::map<point3D_t, Point3D> points3D;
  std::map<camera_t, Housing> housings;  // cameras behind a port
  // rigs.{bin,txt} and frames.{bin,txt} of a COLMAP 3.12+ model; empty for
  // an older one (read and written only when present).
  std::map<uint32_t, ModelRig> rigs;
  std::map<uint32_t, ModelFrame> frames;

  // Throws InputError (prefixed by `context`) on dangling references: images
  // of unknown cameras, tracks naming unknown images or observations,
  // housings of unknown cameras, invalid camera or housing parameters. With
  // `extension` (".bin", ".txt"), `context` is the model's folder and the
  // message names the file: context/images.bin, context/housings.txt.
  void Validate(const std::string& context, const std::string& extension = "") const;
};

enum class ModelFormat { kBinary, kText };

// Reads cameras/images/points3D from `dir` (.bin preferred over .txt when
// both exist, as COLMAP does) and housings.txt if present. Throws InputError
// naming the file for missing, truncated or malformed files.
SparseModel ReadSparseModel(const std::filesystem::path& dir);
// Writes into `dir` (created if needed) atomically per file: each is written
// to a temporary and renamed, so a failure leaves no partial file.
// housings.txt is written only if the model has housings.
void WriteSparseModel(const SparseModel& model, const std::filesystem::path& dir,
                      ModelFormat format);

// Individual files (used by the above and by the tests).
std::map<camera_t, Camera> ReadCamerasText(const std::filesystem::path& path);
std::map<image_t, Image> ReadImagesText(const std::filesystem::path& path);
std::map<point3D_t, Point3D> ReadPoints3DText(const std::filesystem::path& path);
std::map<camera_t, Camera> ReadCamerasBinary(const std::filesystem::path& path);
std::map<image_t, Image> ReadImagesBinary(const std::filesystem::path& path);
std::map<point3D_t, Point3D> ReadPoints3DBinary(const std::filesystem::path& path);
void WriteCamerasText(const SparseModel& model, std::ostream& out);
void WriteImagesText(const SparseModel& model, std::ostream& out);
void WritePoints3DText(const SparseModel& model, std::ostream& out);
void WriteCamerasBinary(const SparseModel& model, std::ostream& out);
void WriteImagesBinary(const SparseModel& model, std::ostream& out);
void WritePoints3DBinary(const SparseModel& model, std::ostream& out);

// Rig and frame files (COLMAP 3.12 on; formats of its
// reconstruction_io_{text,binary}.cc at 4.1.0).
std::map<uint32_t, ModelRig> ReadRigsText(const std::filesystem::path& path);
std::map<uint32_t, ModelFrame> ReadFramesText(const std::filesystem::path& path);
std::map<uint32_t, ModelRig> ReadRigsBinary(const std::filesystem::path& path);
std::map<uint32_t, ModelFrame> ReadFramesBinary(const std::filesystem::path& path);
void WriteRigsText(const SparseModel& model, std::ostream& out);
void WriteFramesText(const SparseModel& model, std::ostream& out);
void WriteRigsBinary(const SparseModel& model, std::ostream& out);
void WriteFramesBinary(const SparseModel& model, std::ostream& out);
// What COLMAP 3.12 on makes of a model without rigs and frames: a rig per
// camera (rig id = camera id, the camera its reference) and a frame per
// image (frame id = image id, rig_from_world = the image's cam_from_world).
void AddOneRigPerCamera(SparseModel* model);

// housings.txt: "CAMERA_ID MODEL PARAMS..." per line, '#' comments.
std::map<camera_t, Housing> ReadHousingsText(const std::filesystem::path& path);
void WriteHousingsText(const std::map<camera_t, Housing>& housings, std::ostream& out);

// The refractive COLMAP fork's cameras.txt: each line is a COLMAP camera
// followed, optionally, by "FLATPORT|DOMEPORT params...". Fills cameras and
// housings.
void ImportRefractiveCamerasText(const std::filesystem::path& path,
                                 std::map<camera_t, Camera>* cameras,
                                 std::map<camera_t, Housing>* housings);

// Writes `path` through a temporary file in the same directory and renames it
// into place: readers never see a partial file. `write` fills the stream;
// anything it throws removes the temporary and propagates.
void WriteFileAtomically(const std::filesystem::path& path, bool binary,
                         const std::function<void(std::ostream&)>& write);

}  // namespace portcal
