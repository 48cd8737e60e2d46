// The SQL that creates portcal's own tables (COLMAP's: colmap_schemas.cc).
#include "database/schema.h"

namespace portcal {

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
