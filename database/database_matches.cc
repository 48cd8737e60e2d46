// The matches and two_view_geometries tables of the Database.
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>

#include "colmap_ext/util/error.h"
#include "database/database.h"

namespace portcal {
namespace {

std::vector<uint32_t> FlattenMatches(const FeatureMatches& matches, bool swap) {
  std::vector<uint32_t> flat(2 * matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    flat[2 * i] = swap ? matches[i].point2D_idx2 : matches[i].point2D_idx1;
    flat[2 * i + 1] = swap ? matches[i].point2D_idx1 : matches[i].point2D_idx2;
  }
  return flat;
}

// `where` names the row for a message (a query, so made only on an error).
using Where = std::function<std::string()>;

FeatureMatches MatchesFromBlob(const std::vector<uint8_t>& blob, int64_t rows, int64_t cols,
                               const Where& where) {
  if (rows < 0 || (rows > 0 && cols != 2) ||
      blob.size() != static_cast<size_t>(rows) * 2 * sizeof(uint32_t)) {
    throw DatabaseError(where() + ": matches blob is not uint32 x 2 (" + std::to_string(rows) +
                        " x " + std::to_string(cols) + ")");
  }
  FeatureMatches matches(rows);
  for (int64_t i = 0; i < rows; ++i) {
    std::memcpy(&matches[i].point2D_idx1, blob.data() + 8 * i, 4);
    std::memcpy(&matches[i].point2D_idx2, blob.data() + 8 * i + 4, 4);
  }
  return matches;
}

// COLMAP stores F, E, H row-major as 9 float64, qvec as w,x,y,z, tvec as 3.
std::vector<double> RowMajor(const Eigen::Matrix3d& m) {
  std::vector<double> values(9);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) values[3 * r + c] = m(r, c);
  }
  return values;
}

std::vector<double> DoublesFromBlob(const std::vector<uint8_t>& blob) {
  std::vector<double> values(blob.size() / sizeof(double));
  if (!values.empty()) std::memcpy(values.data(), blob.data(), values.size() * 8);
  return values;
}

Eigen::Matrix3d MatrixFromBlob(const std::vector<uint8_t>& blob) {
  const std::vector<double> values = DoublesFromBlob(blob);
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  if (values.size() != 9) return m;  // empty without inliers
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = values[3 * r + c];
  }
  return m;
}

TwoViewGeometry GeometryFromRow(const Statement& stmt, const Where& where) {
  TwoViewGeometry geometry;
  geometry.inlier_matches =
      MatchesFromBlob(stmt.ColumnBlob(3), stmt.ColumnInt64(1), stmt.ColumnInt64(2), where);
  const int64_t config = stmt.ColumnInt64(4);
  if (config < static_cast<int>(TwoViewGeometryConfig::kUndefined) ||
      config > static_cast<int>(TwoViewGeometryConfig::kMultiple)) {
    throw DatabaseError(where() + ": config " + std::to_string(config) +
                        " is none of COLMAP's (0 to 8)");
  }
  geometry.config = static_cast<TwoViewGeometryConfig>(config);
  geometry.F = MatrixFromBlob(stmt.ColumnBlob(5));
  geometry.E = MatrixFromBlob(stmt.ColumnBlob(6));
  geometry.H = MatrixFromBlob(stmt.ColumnBlob(7));
  const std::vector<double> qvec = DoublesFromBlob(stmt.ColumnBlob(8));
  const std::vector<double> tvec = DoublesFromBlob(stmt.ColumnBlob(9));
  const auto finite = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  if (!finite(qvec) || !finite(tvec) || !geometry.F.allFinite() || !geometry.E.allFinite() ||
      !geometry.H.allFinite()) {
    throw InputError(
        where() +
        ": the relative pose or F, E or H holds NaN or inf (a damaged or edited database: "
        "match these images again)");
  }
  if (qvec.size() == 4 && tvec.size() == 3) {
    geometry.cam2_from_cam1 =
        Rigid3d(QuaternionFromWxyz(Eigen::Vector4d(qvec[0], qvec[1], qvec[2], qvec[3])),
                Eigen::Vector3d(tvec[0], tvec[1], tvec[2]));
  }
  return geometry;
}

}  // namespace

std::string Database::PairLabel(image_pair_t pair_id) {
  image_t image_id1 = 0, image_id2 = 0;
  PairIdToImagePair(pair_id, &image_id1, &image_id2);
  return "pair " + std::to_string(pair_id) + " (" + ImageLabel(image_id1) + ", " +
         ImageLabel(image_id2) + ")";
}

void Database::WriteMatches(image_t image_id1, image_t image_id2, const FeatureMatches& matches) {
  const std::vector<uint32_t> flat = FlattenMatches(matches, SwapImagePair(image_id1, image_id2));
  Statement& stmt =
      Prepare("write_matches",
              "INSERT OR REPLACE INTO matches(pair_id, rows, cols, data) VALUES(?, ?, 2, ?);");
  stmt.Bind(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)))
      .Bind(2, static_cast<int64_t>(matches.size()))
      .BindBlob(3, flat.data(), flat.size() * sizeof(uint32_t));
  stmt.Execute();
}

FeatureMatches Database::ReadMatches(image_t image_id1, image_t image_id2) {
  Statement& stmt =
      Prepare("read_matches", "SELECT rows, cols, data FROM matches WHERE pair_id=?;");
  stmt.Bind(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  if (!stmt.Step()) return {};
  FeatureMatches matches = MatchesFromBlob(
      stmt.ColumnBlob(2), stmt.ColumnInt64(0), stmt.ColumnInt64(1),
      [&] { return path_ + ": matches of " + PairLabel(ImagePairToPairId(image_id1, image_id2)); });
  if (SwapImagePair(image_id1, image_id2)) {
    for (FeatureMatch& match : matches) std::swap(match.point2D_idx1, match.point2D_idx2);
  }
  return matches;
}

std::vector<std::pair<image_pair_t, FeatureMatches>> Database::ReadAllMatches() {
  Statement& stmt = Prepare("read_all_matches",
                            "SELECT pair_id, rows, cols, data FROM matches ORDER BY pair_id;");
  std::vector<std::pair<image_pair_t, FeatureMatches>> all;
  while (stmt.Step()) {
    const image_pair_t pair_id = stmt.ColumnInt64(0);
    all.emplace_back(pair_id,
                     MatchesFromBlob(stmt.ColumnBlob(3), stmt.ColumnInt64(1), stmt.ColumnInt64(2),
                                     [&] { return path_ + ": matches of " + PairLabel(pair_id); }));
  }
  return all;
}

void Database::WriteTwoViewGeometry(image_t image_id1, image_t image_id2,
                                    const TwoViewGeometry& geometry_in) {
  const TwoViewGeometry geometry =
      SwapImagePair(image_id1, image_id2) ? geometry_in.Inverse() : geometry_in;
  const std::vector<uint32_t> flat = FlattenMatches(geometry.inlier_matches, false);
  // Buffers bound below must outlive Execute().
  const std::vector<double> F = RowMajor(geometry.F);
  const std::vector<double> E = RowMajor(geometry.E);
  const std::vector<double> H = RowMajor(geometry.H);
  const Eigen::Vector4d qvec = QuaternionToWxyz(geometry.cam2_from_cam1.rotation);
  const Eigen::Vector3d tvec = geometry.cam2_from_cam1.translation;
  const bool has_inliers = !geometry.inlier_matches.empty();
  Statement& stmt = Prepare("write_geometry",
                            "INSERT OR REPLACE INTO two_view_geometries(pair_id, rows, cols, data, "
                            "config, F, E, H, qvec, tvec) VALUES(?, ?, 2, ?, ?, ?, ?, ?, ?, ?);");
  stmt.Bind(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)))
      .Bind(2, static_cast<int64_t>(geometry.inlier_matches.size()))
      .BindBlob(3, flat.data(), flat.size() * sizeof(uint32_t))
      .Bind(4, static_cast<int64_t>(geometry.config));
  // COLMAP 3.x: the five blobs always (zeros, the identity), empty without
  // inliers. COLMAP 4: NULL for what was not estimated, which its
  // migration tells by the same zeros and identity.
  const bool null_for_unset = layout_.NullForUnset();
  const bool has_pose =
      !(geometry.cam2_from_cam1.rotation.coeffs() == Eigen::Quaterniond::Identity().coeffs() &&
        geometry.cam2_from_cam1.translation.isZero(0));
  const auto bind_matrix = [&](int index, const std::vector<double>& values,
                               const Eigen::Matrix3d& m) {
    if (null_for_unset && (!has_inliers || m.isZero(0))) {
      stmt.BindNull(index);
    } else {
      stmt.BindBlob(index, values.data(), has_inliers ? 72 : 0);
    }
  };
  bind_matrix(5, F, geometry.F);
  bind_matrix(6, E, geometry.E);
  bind_matrix(7, H, geometry.H);
  if (null_for_unset && (!has_inliers || !has_pose)) {
    stmt.BindNull(8).BindNull(9);
  } else {
    stmt.BindBlob(8, qvec.data(), has_inliers ? 32 : 0)
        .BindBlob(9, tvec.data(), has_inliers ? 24 : 0);
  }
  stmt.Execute();
}

std::optional<TwoViewGeometry> Database::ReadTwoViewGeometry(image_t image_id1, image_t image_id2) {
  Statement& stmt = Prepare("read_geometry",
                            "SELECT pair_id, rows, cols, data, config, F, E, H, qvec, tvec FROM "
                            "two_view_geometries WHERE pair_id=?;");
  stmt.Bind(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  if (!stmt.Step()) return std::nullopt;
  const TwoViewGeometry geometry = GeometryFromRow(stmt, [&] {
    return path_ + ": two_view_geometries of " + PairLabel(ImagePairToPairId(image_id1, image_id2));
  });
  return SwapImagePair(image_id1, image_id2) ? geometry.Inverse() : geometry;
}

std::vector<std::pair<image_pair_t, TwoViewGeometry>> Database::ReadTwoViewGeometries() {
  Statement& stmt = Prepare("read_all_geometries",
                            "SELECT pair_id, rows, cols, data, config, F, E, H, qvec, tvec FROM "
                            "two_view_geometries ORDER BY pair_id;");
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> all;
  while (stmt.Step()) {
    const image_pair_t pair_id = stmt.ColumnInt64(0);
    all.emplace_back(pair_id, GeometryFromRow(stmt, [&] {
                       return path_ + ": two_view_geometries of " + PairLabel(pair_id);
                     }));
  }
  return all;
}

std::vector<image_pair_t> Database::ReadMatchPairIds() {
  Statement& stmt = Prepare("read_match_pair_ids", "SELECT pair_id FROM matches ORDER BY pair_id;");
  std::vector<image_pair_t> pair_ids;
  while (stmt.Step()) pair_ids.push_back(static_cast<image_pair_t>(stmt.ColumnInt64(0)));
  return pair_ids;
}

std::vector<image_pair_t> Database::ReadTwoViewGeometryPairIds() {
  Statement& stmt = Prepare("read_geometry_pair_ids",
                            "SELECT pair_id FROM two_view_geometries ORDER BY pair_id;");
  std::vector<image_pair_t> pair_ids;
  while (stmt.Step()) pair_ids.push_back(static_cast<image_pair_t>(stmt.ColumnInt64(0)));
  return pair_ids;
}

std::vector<std::pair<image_pair_t, int>> Database::ReadTwoViewGeometryNumInliers() {
  Statement& stmt =
      Prepare("read_geometry_num_inliers",
              "SELECT pair_id, rows FROM two_view_geometries WHERE rows > 0 ORDER BY pair_id;");
  std::vector<std::pair<image_pair_t, int>> counts;
  while (stmt.Step()) {
    counts.emplace_back(static_cast<image_pair_t>(stmt.ColumnInt64(0)),
                        static_cast<int>(std::min<int64_t>(stmt.ColumnInt64(1), 1 << 30)));
  }
  return counts;
}

void Database::DeleteMatchesOfImage(image_t image_id) {
  // pair_id = id1 * kMaxNumImages + id2: the image is id1 or id2.
  for (const char* table : {"matches", "two_view_geometries"}) {
    Statement stmt(db_, path_,
                   std::string("DELETE FROM ") + table +
                       " WHERE pair_id / 2147483647 = ?1 OR pair_id % 2147483647 = ?1;");
    stmt.Bind(1, static_cast<int64_t>(image_id));
    stmt.Execute();
  }
}

void Database::DeleteImage(image_t image_id) {
  DeleteMatchesOfImage(image_id);
  if (layout_.rigs_and_frames) DeleteFrames(image_id);
  if (layout_.pose_priors != ColmapLayout::PosePriors::kNone) DeletePosePriorRows(image_id);
  // Explicitly, not by ON DELETE CASCADE: COLMAP opens databases without
  // foreign keys enforced, and so may whoever wrote this one.
  for (const char* table :
       {"keypoints", "descriptors", "portcal_target_observations", "portcal_target_detections",
        "portcal_marker_detections", "portcal_unmasked_features", "images"}) {
    Statement stmt(db_, path_, std::string("DELETE FROM ") + table + " WHERE image_id = ?1;");
    stmt.Bind(1, static_cast<int64_t>(image_id));
    stmt.Execute();
  }
}

int64_t Database::NumCameras() { return QueryInt("SELECT count(*) FROM cameras;"); }
int64_t Database::NumImages() { return QueryInt("SELECT count(*) FROM images;"); }
int64_t Database::NumKeypoints() {
  return QueryInt("SELECT COALESCE(SUM(rows), 0) FROM keypoints;");
}
int64_t Database::NumDescriptors() {
  return QueryInt("SELECT COALESCE(SUM(rows), 0) FROM descriptors;");
}
int64_t Database::NumMatches() { return QueryInt("SELECT COALESCE(SUM(rows), 0) FROM matches;"); }
int64_t Database::NumInlierMatches() {
  return QueryInt("SELECT COALESCE(SUM(rows), 0) FROM two_view_geometries;");
}
int64_t Database::NumMatchedImagePairs() {
  return QueryInt("SELECT count(*) FROM matches WHERE rows > 0;");
}
int64_t Database::NumVerifiedImagePairs() {
  return QueryInt("SELECT count(*) FROM two_view_geometries WHERE rows > 0;");
}

}  // namespace portcal
