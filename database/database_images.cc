// Database: cameras and images, with each image's pose prior where the
// layout keeps it and its rig and frame where the layout has them.
#include <sqlite3.h>

#include <cmath>
#include <cstring>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/image_name.h"
#include "database/database.h"

namespace portcal {
namespace {

std::vector<double> DoublesOf(const std::vector<uint8_t>& blob) {
  std::vector<double> values(blob.size() / sizeof(double));
  if (!values.empty()) std::memcpy(values.data(), blob.data(), values.size() * sizeof(double));
  return values;
}

}  // namespace

camera_t Database::WriteCamera(const Camera& camera, bool use_camera_id) {
  camera.Validate(path_ + ": camera");
  Statement& stmt = Prepare("write_camera",
                            "INSERT INTO cameras(camera_id, model, width, height, params, "
                            "prior_focal_length) VALUES(?, ?, ?, ?, ?, ?);");
  if (use_camera_id) {
    stmt.Bind(1, static_cast<int64_t>(camera.camera_id));
  } else {
    stmt.BindNull(1);
  }
  stmt.Bind(2, static_cast<int64_t>(camera.model_id))
      .Bind(3, static_cast<int64_t>(camera.width))
      .Bind(4, static_cast<int64_t>(camera.height))
      .BindBlob(5, camera.params.data(), camera.params.size() * sizeof(double))
      .Bind(6, static_cast<int64_t>(camera.has_prior_focal_length));
  stmt.Execute();
  return static_cast<camera_t>(sqlite3_last_insert_rowid(db_));
}

void Database::UpdateCamera(const Camera& camera) {
  camera.Validate(path_ + ": camera");
  Statement& stmt = Prepare("update_camera",
                            "UPDATE cameras SET model=?, width=?, height=?, params=?, "
                            "prior_focal_length=? WHERE camera_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera.model_id))
      .Bind(2, static_cast<int64_t>(camera.width))
      .Bind(3, static_cast<int64_t>(camera.height))
      .BindBlob(4, camera.params.data(), camera.params.size() * sizeof(double))
      .Bind(5, static_cast<int64_t>(camera.has_prior_focal_length))
      .Bind(6, static_cast<int64_t>(camera.camera_id));
  stmt.Execute();
}

bool Database::DeleteCameraIfUnused(camera_t camera_id) {
  Statement& stmt = Prepare("delete_unused_camera",
                            "DELETE FROM cameras WHERE camera_id=? AND NOT EXISTS "
                            "(SELECT 1 FROM images WHERE images.camera_id=?);");
  stmt.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, static_cast<int64_t>(camera_id));
  stmt.Execute();
  if (sqlite3_changes(db_) == 0) return false;
  Statement& housing = Prepare("delete_housing", "DELETE FROM portcal_housings WHERE camera_id=?;");
  housing.Bind(1, static_cast<int64_t>(camera_id));
  housing.Execute();
  if (layout_.rigs_and_frames) {
    // The camera's sensor row, and its rig when nothing else is left in it.
    Statement sensor(db_, path_, "DELETE FROM rig_sensors WHERE sensor_id=? AND sensor_type=?;");
    sensor.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, kSensorTypeCamera).Execute();
    Statement rig(
        db_, path_,
        "DELETE FROM rigs WHERE ref_sensor_id=? AND ref_sensor_type=? AND NOT EXISTS (SELECT 1 "
        "FROM frames "
        "WHERE frames.rig_id=rigs.rig_id) AND NOT EXISTS (SELECT 1 FROM rig_sensors WHERE "
        "rig_sensors.rig_id=rigs.rig_id);");
    rig.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, kSensorTypeCamera).Execute();
  }
  return true;
}

namespace {

Camera CameraFromRow(const Statement& stmt, const std::string& path) {
  Camera camera;
  camera.camera_id = static_cast<camera_t>(stmt.ColumnInt64(0));
  camera.model_id = static_cast<int>(stmt.ColumnInt64(1));
  camera.width = stmt.ColumnInt64(2);
  camera.height = stmt.ColumnInt64(3);
  camera.params = DoublesOf(stmt.ColumnBlob(4));
  camera.has_prior_focal_length = stmt.ColumnInt64(5) != 0;
  camera.Validate(path + ": camera " + std::to_string(camera.camera_id));
  return camera;
}

// An images row: image_id, name, camera_id, then the prior: prior_qw..tz
// (legacy) or the pose_priors row's position blob (3.10 on).
DatabaseImage ImageFromRow(const Statement& stmt, bool legacy_priors, const std::string& path) {
  DatabaseImage image;
  image.image_id = static_cast<image_t>(stmt.ColumnInt64(0));
  image.name = stmt.ColumnText(1);
  // A name no model file could hold (colmap_ext/util/image_name.h).
  CheckImageName(image.name, path + ": image " + std::to_string(image.image_id));
  image.camera_id = static_cast<camera_t>(stmt.ColumnInt64(2));
  if (!legacy_priors) {
    const std::vector<double> position = DoublesOf(stmt.ColumnBlob(3));
    if (position.size() == 3 && std::isfinite(position[0]) && std::isfinite(position[1]) &&
        std::isfinite(position[2])) {
      image.position_prior = Eigen::Vector3d(position[0], position[1], position[2]);
    }
    return image;
  }
  bool has_prior = true;
  double prior[7];
  for (int i = 0; i < 7; ++i) {
    prior[i] = stmt.ColumnDouble(3 + i);
    has_prior = has_prior && std::isfinite(prior[i]);
  }
  if (has_prior) {
    image.cam_from_world_prior = Rigid3d(
        QuaternionFromWxyz(Eigen::Vector4d(prior[0], prior[1], prior[2], prior[3])).normalized(),
        Eigen::Vector3d(prior[4], prior[5], prior[6]));
  } else if (std::isfinite(prior[4]) && std::isfinite(prior[5]) && std::isfinite(prior[6])) {
    image.position_prior = Eigen::Vector3d(prior[4], prior[5], prior[6]);
  }
  return image;
}

// The SELECT of images with their priors where `layout` keeps them (COLMAP
// 3.10 on reads pose_priors only, even where old prior_* columns remain).
std::string SelectImages(const ColmapLayout& layout) {
  switch (layout.pose_priors) {
    case ColmapLayout::PosePriors::kNone:
      return "SELECT image_id, name, camera_id, prior_qw, prior_qx, prior_qy, prior_qz, prior_tx, "
             "prior_ty, "
             "prior_tz FROM images";
    case ColmapLayout::PosePriors::kPerImage:
      return "SELECT images.image_id, name, camera_id, pose_priors.position FROM images LEFT JOIN "
             "pose_priors "
             "ON pose_priors.image_id = images.image_id";
    default:
      return "SELECT images.image_id, name, camera_id, pose_priors.position FROM images LEFT JOIN "
             "pose_priors "
             "ON pose_priors.corr_data_id = images.image_id AND pose_priors.corr_sensor_type = " +
             std::to_string(kSensorTypeCamera);
  }
}

}  // namespace

std::optional<Camera> Database::ReadCamera(camera_t camera_id) {
  Statement& stmt = Prepare("read_camera", "SELECT * FROM cameras WHERE camera_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera_id));
  if (!stmt.Step()) return std::nullopt;
  return CameraFromRow(stmt, path_);
}

std::vector<Camera> Database::ReadAllCameras() {
  Statement& stmt = Prepare("read_cameras", "SELECT * FROM cameras ORDER BY camera_id;");
  std::vector<Camera> cameras;
  while (stmt.Step()) cameras.push_back(CameraFromRow(stmt, path_));
  return cameras;
}

image_t Database::WriteImage(const DatabaseImage& image, bool use_image_id) {
  if (image.name.empty()) throw InputError(path_ + ": image without a name");
  // prior_* only where the layout keeps the priors there (3.8, 3.9); a 3.8
  // database that a 3.10 opened keeps the columns, left NULL.
  const bool legacy_priors = layout_.pose_priors == ColmapLayout::PosePriors::kNone;
  Statement& stmt = Prepare(
      "write_image",
      layout_.image_prior_columns
          ? "INSERT INTO images(image_id, name, camera_id, prior_qw, prior_qx, prior_qy, prior_qz, "
            "prior_tx, prior_ty, prior_tz) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?);"
          : "INSERT INTO images(image_id, name, camera_id) VALUES(?, ?, ?);");
  if (use_image_id) {
    stmt.Bind(1, static_cast<int64_t>(image.image_id));
  } else {
    stmt.BindNull(1);
  }
  stmt.Bind(2, image.name).Bind(3, static_cast<int64_t>(image.camera_id));
  if (layout_.image_prior_columns) {
    for (int i = 4; i <= 10; ++i) stmt.BindNull(i);
    if (legacy_priors && image.cam_from_world_prior) {
      const Eigen::Vector4d wxyz = QuaternionToWxyz(image.cam_from_world_prior->rotation);
      for (int i = 0; i < 4; ++i) stmt.Bind(4 + i, wxyz[i]);
      for (int i = 0; i < 3; ++i) stmt.Bind(8 + i, image.cam_from_world_prior->translation[i]);
    } else if (legacy_priors && image.position_prior) {
      for (int i = 0; i < 3; ++i) stmt.Bind(8 + i, (*image.position_prior)[i]);
    }
  }
  stmt.Execute();
  const image_t image_id = static_cast<image_t>(sqlite3_last_insert_rowid(db_));
  if (!legacy_priors) {
    // pose_priors hold positions only: a full pose prior keeps its centre.
    const std::optional<Eigen::Vector3d> position = image.PriorPosition();
    if (position) WritePosePriorRow(image_id, image.camera_id, *position);
  }
  if (layout_.rigs_and_frames) AddFrame(image_id, image.camera_id);
  return image_id;
}

void Database::UpdateImageCamera(image_t image_id, camera_t camera_id) {
  Statement& stmt =
      Prepare("update_image_camera", "UPDATE images SET camera_id=? WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, static_cast<int64_t>(image_id));
  stmt.Execute();
  if (sqlite3_changes(db_) != 1) {
    throw InputError(path_ + ": no image with id " + std::to_string(image_id) + " to give camera " +
                     std::to_string(camera_id));
  }
  if (layout_.rigs_and_frames) {
    DeleteFrames(image_id);
    AddFrame(image_id, camera_id);
  }
  if (layout_.pose_priors == ColmapLayout::PosePriors::kPerData) {
    Statement prior(
        db_, path_,
        "UPDATE pose_priors SET corr_sensor_id=? WHERE corr_data_id=? AND corr_sensor_type=?;");
    prior.Bind(1, static_cast<int64_t>(camera_id)).Bind(2, static_cast<int64_t>(image_id));
    prior.Bind(3, kSensorTypeCamera).Execute();
  }
}

void Database::UpdatePositionPrior(image_t image_id,
                                   const std::optional<Eigen::Vector3d>& position) {
  const std::optional<DatabaseImage> image = ReadImage(image_id);
  if (!image) {
    throw InputError(path_ + ": no image with id " + std::to_string(image_id) +
                     " for a position prior");
  }
  if (layout_.pose_priors != ColmapLayout::PosePriors::kNone) {
    DeletePosePriorRows(image_id);
    if (position) WritePosePriorRow(image_id, image->camera_id, *position);
    return;
  }
  Statement& stmt = Prepare("update_position_prior",
                            "UPDATE images SET prior_qw=NULL, prior_qx=NULL, prior_qy=NULL, "
                            "prior_qz=NULL, prior_tx=?, prior_ty=?, prior_tz=? WHERE image_id=?;");
  for (int i = 0; i < 3; ++i) {
    if (position) {
      stmt.Bind(1 + i, (*position)[i]);
    } else {
      stmt.BindNull(1 + i);
    }
  }
  stmt.Bind(4, static_cast<int64_t>(image_id));
  stmt.Execute();
}

std::optional<DatabaseImage> Database::ReadImage(image_t image_id) {
  Statement& stmt = Prepare("read_image", SelectImages(layout_) + " WHERE images.image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return std::nullopt;
  return ImageFromRow(stmt, layout_.pose_priors == ColmapLayout::PosePriors::kNone, path_);
}

std::optional<DatabaseImage> Database::ReadImageWithName(const std::string& name) {
  Statement& stmt = Prepare("read_image_name", SelectImages(layout_) + " WHERE name=?;");
  stmt.Bind(1, name);
  if (!stmt.Step()) return std::nullopt;
  return ImageFromRow(stmt, layout_.pose_priors == ColmapLayout::PosePriors::kNone, path_);
}

std::vector<DatabaseImage> Database::ReadAllImages() {
  Statement& stmt = Prepare("read_images", SelectImages(layout_) + " ORDER BY images.image_id;");
  std::vector<DatabaseImage> images;
  while (stmt.Step())
    images.push_back(
        ImageFromRow(stmt, layout_.pose_priors == ColmapLayout::PosePriors::kNone, path_));
  return images;
}

}  // namespace portcal
