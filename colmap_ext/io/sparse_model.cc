#include "colmap_ext/io/sparse_model.h"

#include <fstream>
#include <map>
#include <set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/image_name.h"

namespace fs = std::filesystem;

namespace portcal {

void SparseModel::Validate(const std::string& context, const std::string& extension) const {
  // Read from files, the messages name the file whose row is at fault.
  const auto in = [&](const std::string& file) {
    return extension.empty() ? context : (fs::path(context) / (file + extension)).string();
  };
  for (const auto& [camera_id, camera] : cameras) {
    camera.Validate(in("cameras") + ": camera " + std::to_string(camera_id));
  }
  std::map<std::string, image_t> image_of_name;
  for (const auto& [image_id, image] : images) {
    CheckImageName(image.name, in("images") + ": image " + std::to_string(image_id));
    const std::string where =
        in("images") + ": image " + std::to_string(image_id) + " (" + image.name + ")";
    const auto [other, inserted] = image_of_name.emplace(image.name, image_id);
    if (!inserted) {
      throw InputError(where + " has the name of image " + std::to_string(other->second) +
                       " (names identify images in databases and image folders)");
    }
    if (cameras.count(image.camera_id) == 0) {
      throw InputError(where + " refers to unknown camera " + std::to_string(image.camera_id));
    }
    if (!image.cam_from_world.rotation.coeffs().allFinite() ||
        !image.cam_from_world.translation.allFinite()) {
      throw InputError(where + " has a non-finite pose");
    }
    // The readers normalise; a zero quaternion stays zero and is no rotation.
    if (std::abs(image.cam_from_world.rotation.norm() - 1) > 1e-3) {
      throw InputError(where + " has a rotation quaternion of norm " +
                       std::to_string(image.cam_from_world.rotation.norm()) + ", not a rotation");
    }
    for (const Point2D& point2D : image.points2D) {
      if (!point2D.xy.allFinite()) throw InputError(where + " has a non-finite 2D point");
      if (point2D.point3D_id != kInvalidPoint3DId && points3D.count(point2D.point3D_id) == 0) {
        throw InputError(where + " refers to unknown 3D point " +
                         std::to_string(point2D.point3D_id));
      }
    }
  }
  for (const auto& [point3D_id, point3D] : points3D) {
    const std::string where = in("points3D") + ": 3D point " + std::to_string(point3D_id);
    if (!point3D.xyz.allFinite() || !std::isfinite(point3D.error))
      throw InputError(where + " is not finite");
    for (const TrackElement& element : point3D.track) {
      const auto image = images.find(element.image_id);
      if (image == images.end() || element.point2D_idx >= image->second.points2D.size()) {
        throw InputError(where + " observes unknown image " + std::to_string(element.image_id) +
                         " / point " + std::to_string(element.point2D_idx));
      }
    }
  }
  const std::string housings_file =
      extension.empty() ? context : (fs::path(context) / "housings.txt").string();
  for (const auto& [camera_id, housing] : housings) {
    if (cameras.count(camera_id) == 0) {
      throw InputError(housings_file + ": housing of unknown camera " + std::to_string(camera_id));
    }
    housing.Validate(housings_file + ": housing of camera " + std::to_string(camera_id));
  }
  const std::string frames_file =
      extension.empty() ? context : (fs::path(context) / ("frames" + extension)).string();
  for (const auto& [frame_id, frame] : frames) {
    const std::string where = frames_file + ": frame " + std::to_string(frame_id);
    if (rigs.count(frame.rig_id) == 0)
      throw InputError(where + " of unknown rig " + std::to_string(frame.rig_id));
    for (const auto& [sensor, data_id] : frame.data) {
      if (sensor.type == kModelSensorCamera && cameras.count(sensor.id) == 0) {
        throw InputError(where + " holds data of unknown camera " + std::to_string(sensor.id));
      }
    }
  }
}

SparseModel ReadSparseModel(const fs::path& dir) {
  if (!fs::is_directory(dir)) {
    throw InputError(dir.string() + ": not a directory with a sparse model");
  }
  SparseModel model;
  std::string extension = ".txt";
  if (fs::exists(dir / "cameras.bin") && fs::exists(dir / "images.bin") &&
      fs::exists(dir / "points3D.bin")) {
    extension = ".bin";
    model.cameras = ReadCamerasBinary(dir / "cameras.bin");
    model.images = ReadImagesBinary(dir / "images.bin");
    model.points3D = ReadPoints3DBinary(dir / "points3D.bin");
    if (fs::exists(dir / "rigs.bin") && fs::exists(dir / "frames.bin")) {
      model.rigs = ReadRigsBinary(dir / "rigs.bin");
      model.frames = ReadFramesBinary(dir / "frames.bin");
    }
  } else if (fs::exists(dir / "cameras.txt") && fs::exists(dir / "images.txt") &&
             fs::exists(dir / "points3D.txt")) {
    // Accepts the refractive fork's cameras.txt too (port after the camera).
    ImportRefractiveCamerasText(dir / "cameras.txt", &model.cameras, &model.housings);
    model.images = ReadImagesText(dir / "images.txt");
    model.points3D = ReadPoints3DText(dir / "points3D.txt");
    if (fs::exists(dir / "rigs.txt") && fs::exists(dir / "frames.txt")) {
      model.rigs = ReadRigsText(dir / "rigs.txt");
      model.frames = ReadFramesText(dir / "frames.txt");
    }
  } else {
    throw InputError(dir.string() + ": no cameras/images/points3D .bin or .txt files");
  }
  if (fs::exists(dir / "housings.txt")) {
    if (!model.housings.empty()) {
      throw InputError(dir.string() +
                       ": housings given both in cameras.txt (refractive fork "
                       "format) and in housings.txt; keep one");
    }
    model.housings = ReadHousingsText(dir / "housings.txt");
  }
  model.Validate(dir.string(), extension);
  return model;
}

void WriteFileAtomically(const fs::path& path, bool binary,
                         const std::function<void(std::ostream&)>& write) {
  const fs::path tmp = path.string() + ".tmp";
  try {
    {
      std::ofstream out(tmp, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
      if (!out) throw InputError(tmp.string() + ": cannot open for writing");
      write(out);
      out.flush();
      if (!out) throw InputError(tmp.string() + ": write failed");
    }
    fs::rename(tmp, path);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

namespace {

// images.txt holds a name as the rest of its line, and COLMAP 3.8 reads it
// up to the first space: such a name would come back cut (see
// colmap_ext/util/image_name.h).
void CheckNamesFitText(const SparseModel& model) {
  for (const auto& [image_id, image] : model.images) {
    if (image.name.find(' ') == std::string::npos) continue;
    throw InputError("image " + std::to_string(image_id) + " (" + image.name +
                     "): a name with a space cannot be written to images.txt (COLMAP reads names "
                     "there up to the "
                     "first space); write the model as BIN, which keeps any name");
  }
}

}  // namespace

void WriteSparseModel(const SparseModel& model, const fs::path& dir, ModelFormat format) {
  model.Validate("model to write to " + dir.string());
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) {
    throw InputError(dir.string() + ": cannot create output directory");
  }
  const bool binary = format == ModelFormat::kBinary;
  if (!binary) CheckNamesFitText(model);
  const std::string ext = binary ? ".bin" : ".txt";
  WriteFileAtomically(dir / ("cameras" + ext), binary, [&](std::ostream& out) {
    binary ? WriteCamerasBinary(model, out) : WriteCamerasText(model, out);
  });
  WriteFileAtomically(dir / ("images" + ext), binary, [&](std::ostream& out) {
    binary ? WriteImagesBinary(model, out) : WriteImagesText(model, out);
  });
  WriteFileAtomically(dir / ("points3D" + ext), binary, [&](std::ostream& out) {
    binary ? WritePoints3DBinary(model, out) : WritePoints3DText(model, out);
  });
  for (const char* name : {"rigs", "frames"}) {
    const fs::path path = dir / (name + ext);
    if (model.rigs.empty() && model.frames.empty()) {
      if (fs::exists(path)) fs::remove(path);  // stale: would give the images other rigs
      continue;
    }
    WriteFileAtomically(path, binary, [&](std::ostream& out) {
      if (std::string(name) == "rigs") {
        binary ? WriteRigsBinary(model, out) : WriteRigsText(model, out);
      } else {
        binary ? WriteFramesBinary(model, out) : WriteFramesText(model, out);
      }
    });
  }
  const fs::path housings_path = dir / "housings.txt";
  if (!model.housings.empty()) {
    WriteFileAtomically(housings_path, false,
                        [&](std::ostream& out) { WriteHousingsText(model.housings, out); });
  } else if (fs::exists(housings_path)) {
    // A stale sidecar would attach housings to cameras that have none.
    fs::remove(housings_path);
  }
}

}  // namespace portcal
