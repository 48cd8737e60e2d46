// portcal's own tables of the Database (all prefixed portcal_).
#include <cstring>

#include "colmap_ext/util/error.h"
#include "database/database.h"

namespace portcal {

void Database::WriteHousing(camera_t camera_id, const Housing& housing) {
  housing.Validate(path_ + ": housing of camera " + std::to_string(camera_id));
  Statement& stmt =
      Prepare("write_housing",
              "INSERT OR REPLACE INTO portcal_housings(camera_id, model, params) VALUES(?, ?, ?);");
  stmt.Bind(1, static_cast<int64_t>(camera_id))
      .Bind(2, static_cast<int64_t>(housing.model_id))
      .BindBlob(3, housing.params.data(), housing.params.size() * sizeof(double));
  stmt.Execute();
}

namespace {

Housing HousingFromRow(const Statement& stmt, const std::string& path) {
  Housing housing;
  housing.model_id = static_cast<int>(stmt.ColumnInt64(1));
  const std::vector<uint8_t> blob = stmt.ColumnBlob(2);
  housing.params.resize(blob.size() / sizeof(double));
  if (!housing.params.empty()) std::memcpy(housing.params.data(), blob.data(), blob.size());
  housing.Validate(path + ": housing of camera " + std::to_string(stmt.ColumnInt64(0)));
  return housing;
}

}  // namespace

std::optional<Housing> Database::ReadHousing(camera_t camera_id) {
  Statement& stmt = Prepare(
      "read_housing", "SELECT camera_id, model, params FROM portcal_housings WHERE camera_id=?;");
  stmt.Bind(1, static_cast<int64_t>(camera_id));
  if (!stmt.Step()) return std::nullopt;
  return HousingFromRow(stmt, path_);
}

std::map<camera_t, Housing> Database::ReadAllHousings() {
  Statement& stmt =
      Prepare("read_housings", "SELECT camera_id, model, params FROM portcal_housings;");
  std::map<camera_t, Housing> housings;
  while (stmt.Step()) {
    housings[static_cast<camera_t>(stmt.ColumnInt64(0))] = HousingFromRow(stmt, path_);
  }
  return housings;
}

void Database::WriteTargetObservations(image_t image_id,
                                       const std::vector<TargetObservation>& rows) {
  Statement& remove =
      Prepare("delete_observations", "DELETE FROM portcal_target_observations WHERE image_id=?;");
  remove.Bind(1, static_cast<int64_t>(image_id)).Execute();
  Statement& insert = Prepare("write_observation",
                              "INSERT INTO portcal_target_observations(image_id, point_id, x, y, "
                              "target_x, target_y, target_z) VALUES(?, ?, ?, ?, ?, ?, ?);");
  for (const TargetObservation& row : rows) {
    if (!row.xy.allFinite() || !row.point_in_target.allFinite()) {
      throw InputError(path_ + ": non-finite target observation in image " +
                       std::to_string(image_id));
    }
    insert.Bind(1, static_cast<int64_t>(image_id))
        .Bind(2, row.point_id)
        .Bind(3, row.xy.x())
        .Bind(4, row.xy.y())
        .Bind(5, row.point_in_target.x())
        .Bind(6, row.point_in_target.y())
        .Bind(7, row.point_in_target.z());
    insert.Execute();
  }
}

std::vector<TargetObservation> Database::ReadTargetObservations(image_t image_id) {
  Statement& stmt = Prepare("read_observations",
                            "SELECT point_id, x, y, target_x, target_y, target_z FROM "
                            "portcal_target_observations WHERE image_id=? ORDER BY point_id;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  std::vector<TargetObservation> rows;
  while (stmt.Step()) {
    TargetObservation row;
    row.point_id = stmt.ColumnInt64(0);
    row.xy = {stmt.ColumnDouble(1), stmt.ColumnDouble(2)};
    row.point_in_target = {stmt.ColumnDouble(3), stmt.ColumnDouble(4), stmt.ColumnDouble(5)};
    rows.push_back(row);
  }
  return rows;
}

void Database::WriteTargetDetectionStatus(image_t image_id, const TargetDetectionStatus& status) {
  Statement& stmt =
      Prepare("write_detection_status",
              "INSERT OR REPLACE INTO portcal_target_detections(image_id, target, found, "
              "num_points, reason) VALUES(?, ?, ?, ?, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .Bind(2, status.target)
      .Bind(3, static_cast<int64_t>(status.found))
      .Bind(4, static_cast<int64_t>(status.num_points))
      .Bind(5, status.reason);
  stmt.Execute();
}

std::optional<TargetDetectionStatus> Database::ReadTargetDetectionStatus(image_t image_id) {
  Statement& stmt = Prepare(
      "read_detection_status",
      "SELECT target, found, num_points, reason FROM portcal_target_detections WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return std::nullopt;
  TargetDetectionStatus status;
  status.target = stmt.ColumnText(0);
  status.found = stmt.ColumnInt64(1) != 0;
  status.num_points = static_cast<int>(stmt.ColumnInt64(2));
  status.reason = stmt.ColumnText(3);
  return status;
}

void Database::WriteMarkerDetections(image_t image_id, const std::vector<MarkerDetection>& rows) {
  Statement& remove =
      Prepare("delete_markers", "DELETE FROM portcal_marker_detections WHERE image_id=?;");
  remove.Bind(1, static_cast<int64_t>(image_id)).Execute();
  Statement& insert =
      Prepare("write_marker",
              "INSERT INTO portcal_marker_detections(image_id, dictionary, marker_id, "
              "x0, y0, x1, y1, x2, y2, x3, y3) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?);");
  for (const MarkerDetection& row : rows) {
    insert.Bind(1, static_cast<int64_t>(image_id))
        .Bind(2, row.dictionary)
        .Bind(3, static_cast<int64_t>(row.marker_id));
    for (int k = 0; k < 4; ++k) {
      if (!row.corners[k].allFinite()) {
        throw InputError(path_ + ": non-finite marker corner in image " + std::to_string(image_id));
      }
      insert.Bind(4 + 2 * k, row.corners[k].x()).Bind(5 + 2 * k, row.corners[k].y());
    }
    insert.Execute();
  }
}

std::vector<MarkerDetection> Database::ReadMarkerDetections(image_t image_id) {
  Statement& stmt = Prepare("read_markers",
                            "SELECT dictionary, marker_id, x0, y0, x1, y1, x2, y2, x3, y3 FROM "
                            "portcal_marker_detections WHERE image_id=? ORDER BY detection_id;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  std::vector<MarkerDetection> rows;
  while (stmt.Step()) {
    MarkerDetection row;
    row.dictionary = stmt.ColumnText(0);
    row.marker_id = static_cast<int>(stmt.ColumnInt64(1));
    for (int k = 0; k < 4; ++k) {
      row.corners[k] = {stmt.ColumnDouble(2 + 2 * k), stmt.ColumnDouble(3 + 2 * k)};
    }
    rows.push_back(row);
  }
  return rows;
}

int64_t Database::WriteStageLog(const StageLogEntry& entry) {
  Statement& stmt = Prepare("write_stage_log",
                            "INSERT INTO portcal_stage_log(stage, options, start_time, end_time, "
                            "status, counts) VALUES(?, ?, ?, ?, ?, ?);");
  stmt.Bind(1, entry.stage)
      .Bind(2, entry.options)
      .Bind(3, entry.start_time)
      .Bind(4, entry.end_time)
      .Bind(5, entry.status)
      .Bind(6, entry.counts);
  stmt.Execute();
  return QueryInt("SELECT last_insert_rowid();");
}

std::vector<StageLogEntry> Database::ReadStageLog() {
  Statement& stmt = Prepare("read_stage_log",
                            "SELECT run_id, stage, options, start_time, end_time, status, counts "
                            "FROM portcal_stage_log ORDER BY run_id;");
  std::vector<StageLogEntry> entries;
  while (stmt.Step()) {
    StageLogEntry entry;
    entry.run_id = stmt.ColumnInt64(0);
    entry.stage = stmt.ColumnText(1);
    entry.options = stmt.ColumnText(2);
    entry.start_time = stmt.ColumnText(3);
    entry.end_time = stmt.ColumnText(4);
    entry.status = stmt.ColumnText(5);
    entry.counts = stmt.ColumnText(6);
    entries.push_back(entry);
  }
  return entries;
}

void Database::WriteUnmaskedFeatures(image_t image_id, const FeatureKeypoints& keypoints,
                                     const FeatureDescriptors& descriptors) {
  static_assert(sizeof(FeatureKeypoint) == 6 * sizeof(float));
  if (static_cast<size_t>(descriptors.rows()) != keypoints.size()) {
    throw DatabaseError(path_ + ": image " + std::to_string(image_id) + ": " +
                        std::to_string(keypoints.size()) + " keypoints but " +
                        std::to_string(descriptors.rows()) + " descriptors");
  }
  Statement& stmt =
      Prepare("write_unmasked",
              "INSERT OR REPLACE INTO portcal_unmasked_features(image_id, rows, keypoints, "
              "descriptors) VALUES(?, ?, ?, ?);");
  stmt.Bind(1, static_cast<int64_t>(image_id))
      .Bind(2, static_cast<int64_t>(keypoints.size()))
      .BindBlob(3, keypoints.data(), keypoints.size() * sizeof(FeatureKeypoint))
      .BindBlob(4, descriptors.data(), descriptors.size());
  stmt.Execute();
}

bool Database::ReadUnmaskedFeatures(image_t image_id, FeatureKeypoints* keypoints,
                                    FeatureDescriptors* descriptors) {
  Statement& stmt = Prepare(
      "read_unmasked",
      "SELECT rows, keypoints, descriptors FROM portcal_unmasked_features WHERE image_id=?;");
  stmt.Bind(1, static_cast<int64_t>(image_id));
  if (!stmt.Step()) return false;
  const int64_t rows = stmt.ColumnInt64(0);
  const std::vector<uint8_t> keypoint_bytes = stmt.ColumnBlob(1);
  const std::vector<uint8_t> descriptor_bytes = stmt.ColumnBlob(2);
  if (rows < 0 ||
      static_cast<int64_t>(keypoint_bytes.size()) !=
          rows * static_cast<int64_t>(sizeof(FeatureKeypoint)) ||
      static_cast<int64_t>(descriptor_bytes.size()) != rows * 128) {
    throw DatabaseError(path_ + ": unmasked features of image " + std::to_string(image_id) +
                        " have invalid blobs (" + std::to_string(rows) + " rows)");
  }
  keypoints->resize(static_cast<size_t>(rows));
  if (rows > 0) std::memcpy(keypoints->data(), keypoint_bytes.data(), keypoint_bytes.size());
  *descriptors = FeatureDescriptors(rows, 128);
  if (rows > 0) std::memcpy(descriptors->data(), descriptor_bytes.data(), descriptor_bytes.size());
  return true;
}

void Database::DeleteUnmaskedFeatures(image_t image_id) {
  Prepare("delete_unmasked", "DELETE FROM portcal_unmasked_features WHERE image_id=?;")
      .Bind(1, static_cast<int64_t>(image_id))
      .Execute();
}

int64_t Database::NumImagesWithUnmaskedFeatures() {
  return QueryInt("SELECT count(*) FROM portcal_unmasked_features;");
}

}  // namespace portcal
