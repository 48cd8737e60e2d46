// Database: the rows that newer COLMAP versions keep beside an image —
// its pose prior in pose_priors (3.10 on) and its rig and frame (3.12 on)
// — written as those versions write them.
#include <sqlite3.h>

#include <limits>

#include "colmap_ext/util/error.h"
#include "database/database.h"

namespace portcal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

// COLMAP's image reader: a camera's images go to the rig it is a sensor
// of; a camera in no rig gets one of its own, with it as the reference.
int64_t Database::RigOfCamera(camera_t camera_id) {
  Statement& find =
      Prepare("rig_of_camera",
              "SELECT rig_id FROM rigs WHERE ref_sensor_id=?1 AND ref_sensor_type=?2 UNION "
              "SELECT rig_id FROM rig_sensors WHERE sensor_id=?1 AND sensor_type=?2;");
  find.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, kSensorTypeCamera);
  if (find.Step()) return find.ColumnInt64(0);
  Statement& add = Prepare(
      "write_rig", "INSERT INTO rigs(rig_id, ref_sensor_id, ref_sensor_type) VALUES(NULL, ?, ?);");
  add.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, kSensorTypeCamera).Execute();
  return sqlite3_last_insert_rowid(db_);
}

// A frame of its own per new image, as COLMAP's feature extractor writes
// it (rig_configurator groups frames of a multi-camera rig later).
void Database::AddFrame(image_t image_id, camera_t camera_id) {
  const int64_t rig_id = RigOfCamera(camera_id);
  Statement& frame =
      Prepare("write_frame", "INSERT INTO frames(frame_id, rig_id) VALUES(NULL, ?);");
  frame.Bind(1, rig_id).Execute();
  const int64_t frame_id = sqlite3_last_insert_rowid(db_);
  Statement& data = Prepare(
      "write_frame_data",
      "INSERT INTO frame_data(frame_id, data_id, sensor_id, sensor_type) VALUES(?, ?, ?, ?);");
  data.Bind(1, frame_id)
      .Bind(2, static_cast<int64_t>(image_id))
      .Bind(3, static_cast<int64_t>(camera_id));
  data.Bind(4, kSensorTypeCamera).Execute();
}

// The image leaves its frame; a frame left without data goes too.
void Database::DeleteFrames(image_t image_id) {
  Statement frames(db_, path_,
                   "SELECT frame_id FROM frame_data WHERE data_id=? AND sensor_type=?;");
  frames.Bind(1, static_cast<int64_t>(image_id)).Bind(2, kSensorTypeCamera);
  std::vector<int64_t> frame_ids;
  while (frames.Step()) frame_ids.push_back(frames.ColumnInt64(0));
  Statement data(db_, path_, "DELETE FROM frame_data WHERE data_id=? AND sensor_type=?;");
  data.Bind(1, static_cast<int64_t>(image_id)).Bind(2, kSensorTypeCamera).Execute();
  for (const int64_t frame_id : frame_ids) {
    Statement empty(
        db_, path_,
        "DELETE FROM frames WHERE frame_id=? AND NOT EXISTS (SELECT 1 FROM frame_data WHERE "
        "frame_data.frame_id=frames.frame_id);");
    empty.Bind(1, frame_id).Execute();
  }
}

// A navigation position (Cartesian, metres) without covariance or
// gravity: NaN blobs, as COLMAP writes what it does not know.
void Database::WritePosePriorRow(image_t image_id, camera_t camera_id,
                                 const Eigen::Vector3d& position) {
  const Eigen::Matrix<double, 9, 1> covariance = Eigen::Matrix<double, 9, 1>::Constant(kNaN);
  const Eigen::Vector3d gravity = Eigen::Vector3d::Constant(kNaN);
  if (layout_.pose_priors == ColmapLayout::PosePriors::kPerData) {
    Statement& stmt = Prepare(
        "write_pose_prior",
        "INSERT INTO pose_priors(pose_prior_id, corr_data_id, corr_sensor_id, corr_sensor_type, "
        "position, position_covariance, gravity, coordinate_system) "
        "VALUES(NULL, ?, ?, ?, ?, ?, ?, ?);");
    stmt.Bind(1, static_cast<int64_t>(image_id))
        .Bind(2, static_cast<int64_t>(camera_id))
        .Bind(3, kSensorTypeCamera);
    stmt.BindBlob(4, position.data(), 24)
        .BindBlob(5, covariance.data(), 72)
        .BindBlob(6, gravity.data(), 24);
    stmt.Bind(7, kCoordinateSystemCartesian).Execute();
    return;
  }
  Statement& stmt =
      Prepare("write_pose_prior", layout_.pose_prior_covariance
                                      ? "INSERT OR REPLACE INTO pose_priors(image_id, position, "
                                        "coordinate_system, position_covariance) "
                                        "VALUES(?, ?, ?, ?);"
                                      : "INSERT OR REPLACE INTO pose_priors(image_id, position, "
                                        "coordinate_system) VALUES(?, ?, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .BindBlob(2, position.data(), 24)
      .Bind(3, kCoordinateSystemCartesian);
  if (layout_.pose_prior_covariance) stmt.BindBlob(4, covariance.data(), 72);
  stmt.Execute();
}

void Database::DeletePosePriorRows(image_t image_id) {
  Statement& stmt =
      Prepare("delete_pose_prior", layout_.pose_priors == ColmapLayout::PosePriors::kPerData
                                       ? "DELETE FROM pose_priors WHERE corr_data_id=? AND "
                                         "corr_sensor_type=" +
                                             std::to_string(kSensorTypeCamera) + ";"
                                       : "DELETE FROM pose_priors WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id)).Execute();
}

}  // namespace portcal
