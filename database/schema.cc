// The SQL that creates the schema: COLMAP 3.8's six tables and index,
// character for character as COLMAP writes them (so sqlite_master matches a
// database made by `colmap database_creator`), and portcal's own tables.
#include "database/schema.h"

namespace portcal {

const std::vector<std::string>& ColmapSchemaSql() {
  static const std::vector<std::string> kSql = {
    // cameras
    R"sql(CREATE TABLE IF NOT EXISTS cameras   (camera_id            INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    model                INTEGER                             NOT NULL,    width                INTEGER                             NOT NULL,    height               INTEGER                             NOT NULL,    params               BLOB,    prior_focal_length   INTEGER                             NOT NULL))sql",
    // images
    R"sql(CREATE TABLE IF NOT EXISTS images   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,    name       TEXT                                NOT NULL UNIQUE,    camera_id  INTEGER                             NOT NULL,    prior_qw   REAL,    prior_qx   REAL,    prior_qy   REAL,    prior_qz   REAL,    prior_tx   REAL,    prior_ty   REAL,    prior_tz   REAL,CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),FOREIGN KEY(camera_id) REFERENCES cameras(camera_id)))sql",
    // index_name
    R"sql(CREATE UNIQUE INDEX IF NOT EXISTS index_name ON images(name))sql",
    // keypoints
    R"sql(CREATE TABLE IF NOT EXISTS keypoints   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
    // descriptors
    R"sql(CREATE TABLE IF NOT EXISTS descriptors   (image_id  INTEGER  PRIMARY KEY  NOT NULL,    rows      INTEGER               NOT NULL,    cols      INTEGER               NOT NULL,    data      BLOB,FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
    // matches
    R"sql(CREATE TABLE IF NOT EXISTS matches   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB))sql",
    // two_view_geometries
    R"sql(CREATE TABLE IF NOT EXISTS two_view_geometries   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,    rows     INTEGER               NOT NULL,    cols     INTEGER               NOT NULL,    data     BLOB,    config   INTEGER               NOT NULL,    F        BLOB,    E        BLOB,    H        BLOB,    qvec     BLOB,    tvec     BLOB))sql",
  };
  return kSql;
}

const std::vector<std::string>& PortcalSchemaSql() {
  static const std::vector<std::string> kSql = {
      R"sql(CREATE TABLE IF NOT EXISTS portcal_meta (
  key    TEXT PRIMARY KEY NOT NULL,
  value  TEXT NOT NULL))sql",
      // Housing of a camera: model id (FLATPORT 0, DOMEPORT 1) and float64
      // parameters in the refractive fork's order.
      R"sql(CREATE TABLE IF NOT EXISTS portcal_housings (
  camera_id  INTEGER PRIMARY KEY NOT NULL,
  model      INTEGER NOT NULL,
  params     BLOB NOT NULL,
  FOREIGN KEY(camera_id) REFERENCES cameras(camera_id) ON DELETE CASCADE))sql",
      // Target corners seen in an image: COLMAP pixels and the point's
      // coordinates on the target (metres).
      R"sql(CREATE TABLE IF NOT EXISTS portcal_target_observations (
  image_id  INTEGER NOT NULL,
  point_id  INTEGER NOT NULL,
  x         REAL NOT NULL,
  y         REAL NOT NULL,
  target_x  REAL NOT NULL,
  target_y  REAL NOT NULL,
  target_z  REAL NOT NULL,
  PRIMARY KEY(image_id, point_id),
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
      // Per image and target stage: whether the target was found, how many
      // points were kept, and why not.
      R"sql(CREATE TABLE IF NOT EXISTS portcal_target_detections (
  image_id    INTEGER PRIMARY KEY NOT NULL,
  target      TEXT NOT NULL,
  found       INTEGER NOT NULL,
  num_points  INTEGER NOT NULL,
  reason      TEXT NOT NULL,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
      // ArUco detections: dictionary name, marker id, 4 corners in OpenCV's
      // order (COLMAP pixels).
      R"sql(CREATE TABLE IF NOT EXISTS portcal_marker_detections (
  detection_id  INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,
  image_id      INTEGER NOT NULL,
  dictionary    TEXT NOT NULL,
  marker_id     INTEGER NOT NULL,
  x0 REAL NOT NULL, y0 REAL NOT NULL,
  x1 REAL NOT NULL, y1 REAL NOT NULL,
  x2 REAL NOT NULL, y2 REAL NOT NULL,
  x3 REAL NOT NULL, y3 REAL NOT NULL,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
      R"sql(CREATE INDEX IF NOT EXISTS portcal_marker_detections_image
  ON portcal_marker_detections(image_id))sql",
      // The features of an image as feature_extractor made them, kept by
      // feature_masker before it first masks the image: keypoints (rows x 6
      // float32, COLMAP's layout) and descriptors (rows x 128 uint8). Another
      // mask starts from them. Deleted when the image is extracted again.
      R"sql(CREATE TABLE IF NOT EXISTS portcal_unmasked_features (
  image_id     INTEGER PRIMARY KEY NOT NULL,
  rows         INTEGER NOT NULL,
  keypoints    BLOB,
  descriptors  BLOB,
  FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE))sql",
      // Completed stage runs.
      R"sql(CREATE TABLE IF NOT EXISTS portcal_stage_log (
  run_id      INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,
  stage       TEXT NOT NULL,
  options     TEXT NOT NULL,
  start_time  TEXT NOT NULL,
  end_time    TEXT NOT NULL,
  status      TEXT NOT NULL,
  counts      TEXT NOT NULL))sql",
  };
  return kSql;
}

}  // namespace portcal
