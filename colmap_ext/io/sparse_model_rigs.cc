// rigs and frames files of COLMAP 3.12+ models, text and binary, in the
// layout of COLMAP 4.1.0's reconstruction_io_text.cc and
// reconstruction_io_binary.cc (the sensor type as its name in text, as an
// int in binary; 17 significant digits in text).
#include <locale>
#include <sstream>

#include "colmap_ext/io/binary_reader.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::string SensorTypeName(int type) {
  switch (type) {
    case -1:
      return "INVALID";
    case 0:
      return "CAMERA";
    case 1:
      return "IMU";
    default:
      throw InputError("sensor type " + std::to_string(type) +
                       " is none of COLMAP's (INVALID, CAMERA, IMU)");
  }
}

int SensorTypeOf(const std::string& name, const std::string& where) {
  for (int type = -1; type <= 1; ++type) {
    if (SensorTypeName(type) == name) return type;
  }
  throw InputError(where + ": sensor type '" + name + "' is none of INVALID, CAMERA, IMU");
}

int CheckedSensorType(int type, const std::string& where) {
  if (type < -1 || type > 1)
    throw InputError(where + ": sensor type " + std::to_string(type) + " is none of COLMAP's");
  return type;
}

// Lines of a text file without comments and blank lines, with their numbers.
std::vector<std::pair<int, std::string>> DataLines(const fs::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open");
  std::vector<std::pair<int, std::string>> lines;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

Rigid3d ReadPose(std::istream& in) {
  double w = 0, x = 0, y = 0, z = 0;
  Eigen::Vector3d t;
  in >> w >> x >> y >> z >> t.x() >> t.y() >> t.z();
  return Rigid3d(Eigen::Quaterniond(w, x, y, z), t);
}

void WritePose(std::ostream& out, const Rigid3d& pose) {
  out << pose.rotation.w() << " " << pose.rotation.x() << " " << pose.rotation.y() << " "
      << pose.rotation.z() << " " << pose.translation.x() << " " << pose.translation.y() << " "
      << pose.translation.z();
}

Rigid3d ReadBinaryPose(BinaryReader* in, const char* what) {
  double q[4], t[3];
  for (double& v : q) v = in->ReadFinite(what);
  for (double& v : t) v = in->ReadFinite(what);
  return Rigid3d(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), Eigen::Vector3d(t[0], t[1], t[2]));
}

void WriteBinaryPose(std::ostream& out, const Rigid3d& pose) {
  for (const double v : {pose.rotation.w(), pose.rotation.x(), pose.rotation.y(), pose.rotation.z(),
                         pose.translation.x(), pose.translation.y(), pose.translation.z()}) {
    WriteLittleEndian(out, v);
  }
}

}  // namespace

std::map<uint32_t, ModelRig> ReadRigsText(const fs::path& path) {
  std::map<uint32_t, ModelRig> rigs;
  for (const auto& [number, line] : DataLines(path)) {
    const std::string where = path.string() + ":" + std::to_string(number);
    std::istringstream in(line);
    in.imbue(std::locale::classic());
    uint32_t rig_id = 0;
    uint64_t num_sensors = 0;
    std::string type;
    ModelRig rig;
    in >> rig_id >> num_sensors;
    if (in && num_sensors > 0) {
      ModelSensor ref;
      in >> type >> ref.id;
      if (in) ref.type = SensorTypeOf(type, where);
      rig.ref_sensor = ref;
    }
    for (uint64_t i = 1; in && i < num_sensors; ++i) {
      ModelSensor sensor;
      int has_pose = 0;
      in >> type >> sensor.id >> has_pose;
      if (!in) break;
      sensor.type = SensorTypeOf(type, where);
      rig.sensors.emplace_back(sensor,
                               has_pose == 1 ? std::optional<Rigid3d>(ReadPose(in)) : std::nullopt);
    }
    if (!in)
      throw InputError(where +
                       ": expected RIG_ID NUM_SENSORS REF_SENSOR_TYPE REF_SENSOR_ID SENSORS[]");
    if (!rigs.emplace(rig_id, std::move(rig)).second)
      throw InputError(where + ": rig " + std::to_string(rig_id) + " again");
  }
  return rigs;
}

std::map<uint32_t, ModelFrame> ReadFramesText(const fs::path& path) {
  std::map<uint32_t, ModelFrame> frames;
  for (const auto& [number, line] : DataLines(path)) {
    const std::string where = path.string() + ":" + std::to_string(number);
    std::istringstream in(line);
    in.imbue(std::locale::classic());
    uint32_t frame_id = 0, num_data = 0;
    ModelFrame frame;
    in >> frame_id >> frame.rig_id;
    frame.rig_from_world = ReadPose(in);
    in >> num_data;
    for (uint32_t i = 0; in && i < num_data; ++i) {
      std::string type;
      ModelSensor sensor;
      uint64_t data_id = 0;
      in >> type >> sensor.id >> data_id;
      if (!in) break;
      sensor.type = SensorTypeOf(type, where);
      frame.data.emplace_back(sensor, data_id);
    }
    if (!in)
      throw InputError(where +
                       ": expected FRAME_ID RIG_ID QW QX QY QZ TX TY TZ NUM_DATA_IDS DATA_IDS[]");
    if (!frames.emplace(frame_id, std::move(frame)).second) {
      throw InputError(where + ": frame " + std::to_string(frame_id) + " again");
    }
  }
  return frames;
}

std::map<uint32_t, ModelRig> ReadRigsBinary(const fs::path& path) {
  BinaryReader in(path);
  std::map<uint32_t, ModelRig> rigs;
  const uint64_t count = in.ReadCount("number of rigs", 8);
  for (uint64_t r = 0; r < count; ++r) {
    const uint32_t rig_id = in.Read<uint32_t>("rig id");
    const uint32_t num_sensors = in.Read<uint32_t>("number of sensors");
    ModelRig rig;
    if (num_sensors > 0) {
      ModelSensor ref;
      ref.type = CheckedSensorType(in.Read<int>("sensor type"), path.string());
      ref.id = in.Read<uint32_t>("sensor id");
      rig.ref_sensor = ref;
    }
    for (uint32_t i = 1; i < num_sensors; ++i) {
      ModelSensor sensor;
      sensor.type = CheckedSensorType(in.Read<int>("sensor type"), path.string());
      sensor.id = in.Read<uint32_t>("sensor id");
      const bool has_pose = in.Read<uint8_t>("sensor pose flag") == 1;
      rig.sensors.emplace_back(
          sensor,
          has_pose ? std::optional<Rigid3d>(ReadBinaryPose(&in, "sensor_from_rig")) : std::nullopt);
    }
    if (!rigs.emplace(rig_id, std::move(rig)).second) {
      throw InputError(path.string() + ": rig " + std::to_string(rig_id) + " again");
    }
  }
  return rigs;
}

std::map<uint32_t, ModelFrame> ReadFramesBinary(const fs::path& path) {
  BinaryReader in(path);
  std::map<uint32_t, ModelFrame> frames;
  const uint64_t count = in.ReadCount("number of frames", 64);
  for (uint64_t f = 0; f < count; ++f) {
    const uint32_t frame_id = in.Read<uint32_t>("frame id");
    ModelFrame frame;
    frame.rig_id = in.Read<uint32_t>("rig id");
    frame.rig_from_world = ReadBinaryPose(&in, "rig_from_world");
    const uint32_t num_data = in.Read<uint32_t>("number of data ids");
    for (uint32_t i = 0; i < num_data; ++i) {
      ModelSensor sensor;
      sensor.type = CheckedSensorType(in.Read<int>("sensor type"), path.string());
      sensor.id = in.Read<uint32_t>("sensor id");
      frame.data.emplace_back(sensor, in.Read<uint64_t>("data id"));
    }
    if (!frames.emplace(frame_id, std::move(frame)).second) {
      throw InputError(path.string() + ": frame " + std::to_string(frame_id) + " again");
    }
  }
  return frames;
}

void WriteRigsText(const SparseModel& model, std::ostream& out) {
  out.imbue(std::locale::classic());
  out.precision(17);
  out << "# Rig calib list with one line of data per calib:\n"
      << "#   RIG_ID, NUM_SENSORS, REF_SENSOR_TYPE, REF_SENSOR_ID, SENSORS[] as (SENSOR_TYPE, "
         "SENSOR_ID, HAS_POSE, "
         "[QW, QX, QY, QZ, TX, TY, TZ])\n"
      << "# Number of rigs: " << model.rigs.size() << '\n';
  for (const auto& [rig_id, rig] : model.rigs) {
    out << rig_id << " " << (rig.ref_sensor ? rig.sensors.size() + 1 : 0);
    if (rig.ref_sensor)
      out << " " << SensorTypeName(rig.ref_sensor->type) << " " << rig.ref_sensor->id;
    for (const auto& [sensor, sensor_from_rig] : rig.sensors) {
      out << " " << SensorTypeName(sensor.type) << " " << sensor.id << " "
          << (sensor_from_rig ? 1 : 0);
      if (sensor_from_rig) {
        out << " ";
        WritePose(out, *sensor_from_rig);
      }
    }
    out << '\n';
  }
}

void WriteFramesText(const SparseModel& model, std::ostream& out) {
  out.imbue(std::locale::classic());
  out.precision(17);
  out << "# Frame list with one line of data per frame:\n"
      << "#   FRAME_ID, RIG_ID, RIG_FROM_WORLD[QW, QX, QY, QZ, TX, TY, TZ], NUM_DATA_IDS, "
         "DATA_IDS[] as "
         "(SENSOR_TYPE, SENSOR_ID, DATA_ID)\n"
      << "# Number of frames: " << model.frames.size() << '\n';
  for (const auto& [frame_id, frame] : model.frames) {
    out << frame_id << " " << frame.rig_id << " ";
    WritePose(out, frame.rig_from_world);
    out << " " << frame.data.size();
    for (const auto& [sensor, data_id] : frame.data) {
      out << " " << SensorTypeName(sensor.type) << " " << sensor.id << " " << data_id;
    }
    out << '\n';
  }
}

void WriteRigsBinary(const SparseModel& model, std::ostream& out) {
  WriteLittleEndian<uint64_t>(out, model.rigs.size());
  for (const auto& [rig_id, rig] : model.rigs) {
    WriteLittleEndian<uint32_t>(out, rig_id);
    WriteLittleEndian<uint32_t>(out,
                                static_cast<uint32_t>(rig.ref_sensor ? rig.sensors.size() + 1 : 0));
    if (rig.ref_sensor) {
      WriteLittleEndian<int>(out, rig.ref_sensor->type);
      WriteLittleEndian<uint32_t>(out, rig.ref_sensor->id);
    }
    for (const auto& [sensor, sensor_from_rig] : rig.sensors) {
      WriteLittleEndian<int>(out, sensor.type);
      WriteLittleEndian<uint32_t>(out, sensor.id);
      WriteLittleEndian<uint8_t>(out, sensor_from_rig ? 1 : 0);
      if (sensor_from_rig) WriteBinaryPose(out, *sensor_from_rig);
    }
  }
}

void WriteFramesBinary(const SparseModel& model, std::ostream& out) {
  WriteLittleEndian<uint64_t>(out, model.frames.size());
  for (const auto& [frame_id, frame] : model.frames) {
    WriteLittleEndian<uint32_t>(out, frame_id);
    WriteLittleEndian<uint32_t>(out, frame.rig_id);
    WriteBinaryPose(out, frame.rig_from_world);
    WriteLittleEndian<uint32_t>(out, static_cast<uint32_t>(frame.data.size()));
    for (const auto& [sensor, data_id] : frame.data) {
      WriteLittleEndian<int>(out, sensor.type);
      WriteLittleEndian<uint32_t>(out, sensor.id);
      WriteLittleEndian<uint64_t>(out, data_id);
    }
  }
}

void AddOneRigPerCamera(SparseModel* model) {
  model->rigs.clear();
  model->frames.clear();
  for (const auto& [camera_id, camera] : model->cameras) {
    model->rigs[camera_id].ref_sensor = ModelSensor{kModelSensorCamera, camera_id};
  }
  for (const auto& [image_id, image] : model->images) {
    ModelFrame& frame = model->frames[image_id];
    frame.rig_id = image.camera_id;
    frame.rig_from_world = image.cam_from_world;
    frame.data = {{ModelSensor{kModelSensorCamera, image.camera_id}, image_id}};
  }
}

}  // namespace portcal
