// COLMAP's CREATE statements, character for character as each version runs
// them (so sqlite_master matches a database that version created), split
// where COLMAP runs a table and its index in one call, "%d" filled with
// kMaxNumImages (2147483647). From COLMAP's sources at the tags:
//   3.8                                    src/base/database.cc
//   3.9, 3.10, 3.11.1, 3.12.0              src/colmap/scene/database.cc
//   3.13.0, 4.0.0, 4.1.0                   src/colmap/scene/database_sqlite.cc
// 3.8 = 3.9, 3.12 = 3.13 and 4.0 = 4.1 statement for statement (the
// versions differ in PRAGMA user_version and, 3.9 on, in migrations run
// when COLMAP opens a database).
#include "database/schema.h"

namespace portcal {
namespace {

constexpr const char* kCameras =
    R"sql(CREATE TABLE IF NOT EXISTS cameras   (camera_id            INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    model                INTEGER                             NOT NULL,    width                INTEGER                             NOT NULL,    height               INTEGER                             NOT NULL,    params               BLOB,    prior_focal_length   INTEGER                             NOT NULL))sql";
constexpr const char* kImages38 =
    R"sql(CREATE TABLE IF NOT EXISTS images   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    name       TEXT                                NOT NULL UNIQUE,    camera_id  INTEGER                             NOT NULL,    prior_qw   REAL,    prior_qx   REAL,    prior_qy   REAL,    prior_qz   REAL,    prior_tx   REAL,    prior_ty   REAL,    prior_tz   REAL,CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),FOREIGN KEY(camera_id) REFERENCES cameras(camera_id)))sql";
constexpr const char* kIndexName =
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS index_name ON images(name))sql";
constexpr const char* kKeypoints38 =
    R"sql(CREATE TABLE IF NOT EXISTS keypoints   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kDescriptors38 =
    R"sql(CREATE TABLE IF NOT EXISTS descriptors   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kMatches =
    R"sql(CREATE TABLE IF NOT EXISTS matches   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB))sql";
constexpr const char* kTwoViewGeometries =
    R"sql(CREATE TABLE IF NOT EXISTS two_view_geometries   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB,    config   INTEGER               NOT NULL,    F        BLOB,    E        BLOB,    H        BLOB,    qvec     BLOB,    tvec     BLOB))sql";
constexpr const char* kImages310 =
    R"sql(CREATE TABLE IF NOT EXISTS images   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    name       TEXT                                NOT NULL UNIQUE,    camera_id  INTEGER                             NOT NULL,CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),FOREIGN KEY(camera_id) REFERENCES cameras(camera_id)))sql";
constexpr const char* kPosePriors310 =
    R"sql(CREATE TABLE IF NOT EXISTS pose_priors   (image_id          INTEGER  PRIMARY KEY  NOT NULL,    position          BLOB,    coordinate_system INTEGER               NOT NULL,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kPosePriors311 =
    R"sql(CREATE TABLE IF NOT EXISTS pose_priors   (image_id                   INTEGER  PRIMARY KEY  NOT NULL,    position                   BLOB,    coordinate_system          INTEGER               NOT NULL,    position_covariance        BLOB,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kRigs =
    R"sql(CREATE TABLE IF NOT EXISTS rigs   (rig_id               INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    ref_sensor_id        INTEGER                             NOT NULL,    ref_sensor_type      INTEGER                             NOT NULL))sql";
constexpr const char* kRigRefSensorIndex =
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS rig_ref_sensor_assignment ON    rigs(ref_sensor_id, ref_sensor_type))sql";
constexpr const char* kRigSensors =
    R"sql(CREATE TABLE IF NOT EXISTS rig_sensors   (rig_id               INTEGER                             NOT NULL,    sensor_id            INTEGER                             NOT NULL,    sensor_type          INTEGER                             NOT NULL,    sensor_from_rig      BLOB,FOREIGN KEY(rig_id) REFERENCES rigs(rig_id) ON DELETE CASCADE))sql";
constexpr const char* kRigSensorIndex =
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS rig_sensor_assignment ON    rig_sensors(sensor_id, sensor_type))sql";
constexpr const char* kFrames =
    R"sql(CREATE TABLE IF NOT EXISTS frames   (frame_id             INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    rig_id               INTEGER                             NOT NULL,    FOREIGN KEY(rig_id) REFERENCES rigs(rig_id) ON DELETE CASCADE))sql";
constexpr const char* kFrameData =
    R"sql(CREATE TABLE IF NOT EXISTS frame_data   (frame_id             INTEGER                             NOT NULL,    data_id              INTEGER                             NOT NULL,    sensor_id            INTEGER                             NOT NULL,    sensor_type          INTEGER                             NOT NULL,    FOREIGN KEY(frame_id) REFERENCES frames(frame_id) ON DELETE CASCADE))sql";
constexpr const char* kFrameSensorIndex =
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS frame_sensor_assignment ON    frame_data(data_id, sensor_type))sql";
constexpr const char* kImages312 =
    R"sql(CREATE TABLE IF NOT EXISTS images   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    name       TEXT                                NOT NULL UNIQUE,    camera_id  INTEGER                             NOT NULL,    CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),    FOREIGN KEY(camera_id) REFERENCES cameras(camera_id)))sql";
constexpr const char* kPosePriors312 =
    R"sql(CREATE TABLE IF NOT EXISTS pose_priors   (image_id                   INTEGER  PRIMARY KEY  NOT NULL,    position                   BLOB,    coordinate_system          INTEGER               NOT NULL,    position_covariance        BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kKeypoints312 =
    R"sql(CREATE TABLE IF NOT EXISTS keypoints   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kDescriptors312 =
    R"sql(CREATE TABLE IF NOT EXISTS descriptors   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";
constexpr const char* kPosePriors40 =
    R"sql(CREATE TABLE IF NOT EXISTS pose_priors   (pose_prior_id              INTEGER  PRIMARY KEY  NOT NULL,    corr_data_id               INTEGER               NOT NULL,    corr_sensor_id             INTEGER               NOT NULL,    corr_sensor_type           INTEGER               NOT NULL,    position                   BLOB,    position_covariance        BLOB,    gravity                    BLOB,    coordinate_system          INTEGER               NOT NULL))sql";
constexpr const char* kPosePriorDataIndex =
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS pose_prior_data_assignment ON    pose_priors(corr_data_id, corr_sensor_id, corr_sensor_type))sql";
constexpr const char* kDescriptors40 =
    R"sql(CREATE TABLE IF NOT EXISTS descriptors   (image_id      INTEGER  PRIMARY KEY  NOT NULL,    type          INTEGER               NOT NULL,    rows          INTEGER               NOT NULL,    cols          INTEGER               NOT NULL,    data          BLOB,    FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql";

}  // namespace

const std::vector<std::string>& ColmapSchemaSql(ColmapVersion version) {
  static const std::vector<std::string> k3_9 = {
      kCameras, kImages38, kIndexName, kKeypoints38, kDescriptors38, kMatches, kTwoViewGeometries};
  static const std::vector<std::string> k3_10 = {kCameras,       kImages310,        kIndexName,
                                                 kPosePriors310, kKeypoints38,      kDescriptors38,
                                                 kMatches,       kTwoViewGeometries};
  static const std::vector<std::string> k3_11 = {kCameras,       kImages310,        kIndexName,
                                                 kPosePriors311, kKeypoints38,      kDescriptors38,
                                                 kMatches,       kTwoViewGeometries};
  static const std::vector<std::string> k3_12 = {
      kRigs,          kRigRefSensorIndex, kRigSensors,       kRigSensorIndex, kCameras,
      kFrames,        kFrameData,         kFrameSensorIndex, kImages312,      kIndexName,
      kPosePriors312, kKeypoints312,      kDescriptors312,   kMatches,        kTwoViewGeometries};
  static const std::vector<std::string> k4_1 = {kRigs,         kRigRefSensorIndex,
                                                kRigSensors,   kRigSensorIndex,
                                                kCameras,      kFrames,
                                                kFrameData,    kFrameSensorIndex,
                                                kImages312,    kIndexName,
                                                kPosePriors40, kPosePriorDataIndex,
                                                kKeypoints312, kDescriptors40,
                                                kMatches,      kTwoViewGeometries};
  switch (version) {
    case ColmapVersion::k3_8:
    case ColmapVersion::k3_9:
      return k3_9;
    case ColmapVersion::k3_10:
      return k3_10;
    case ColmapVersion::k3_11:
      return k3_11;
    case ColmapVersion::k3_12:
    case ColmapVersion::k3_13:
      return k3_12;
    default:
      return k4_1;
  }
}

}  // namespace portcal
