// A COLMAP database of any version from 3.8 to 4.1 (colmap_layout.h: the
// layout is read from the tables) plus portcal's own tables, all prefixed
// portcal_. Rows are read from, and written to, where that version keeps
// them, as that version writes them (docs/database.md): pose priors in
// images.prior_* or in pose_priors, a rig and a frame for each new image
// where there are rigs and frames, the descriptors' type, NULL for the
// two-view geometry a COLMAP 4 did not estimate. Tables and columns
// portcal does not know are left as they are.
//
// Stages write inside one Transaction: it rolls back unless committed, so a
// failed or interrupted stage leaves the file as it was.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "database/colmap_layout.h"
#include "database/feature_types.h"
#include "database/lock_wait.h"
#include "database/statement.h"

struct sqlite3;

namespace portcal {

class Database {
 public:
  static constexpr int kPortcalSchemaVersion = 2;

  enum class OpenMode {
    kReadOnly,   // must exist
    kReadWrite,  // must exist
    kCreate,     // created with the full schema if missing
  };

  // Throws DatabaseError naming `path` for: a missing file (unless kCreate),
  // a file that is no SQLite database, a database of a COLMAP version
  // portcal does not know (colmap_layout.h) or of another portcal schema
  // version, or one locked by another process for longer than
  // DatabaseBusyTimeout() (lock_wait.h). kCreate creates a missing file
  // with `version_if_created`'s layout.
  explicit Database(const std::filesystem::path& path, OpenMode mode = OpenMode::kReadWrite,
                    ColmapVersion version_if_created = ColmapVersion::k3_8);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  const std::string& path() const { return path_; }
  const ColmapLayout& layout() const { return layout_; }
  // BEGIN IMMEDIATE; ROLLBACK unless Commit() is called.
  Transaction BeginTransaction();

  // --- COLMAP tables -------------------------------------------------------
  // Inserts; assigns a new id unless `use_camera_id`.
  camera_t WriteCamera(const Camera& camera, bool use_camera_id = false);
  void UpdateCamera(const Camera& camera);
  std::optional<Camera> ReadCamera(camera_t camera_id);
  std::vector<Camera> ReadAllCameras();

  image_t WriteImage(const DatabaseImage& image, bool use_image_id = false);
  std::optional<DatabaseImage> ReadImage(image_t image_id);
  // "image 7 (name.png)" for messages; "image 7" when there is no such row.
  std::string ImageLabel(image_t image_id);
  // "pair N (image 1 (a.png), image 2 (b.png))" for messages.
  std::string PairLabel(image_pair_t pair_id);
  // Sets (or, with nullopt, clears) an image's position prior (Cartesian,
  // metres) where the layout keeps priors; clears any full pose prior.
  void UpdatePositionPrior(image_t image_id, const std::optional<Eigen::Vector3d>& position);
  std::optional<DatabaseImage> ReadImageWithName(const std::string& name);
  // Gives the image another camera (a rerun that imports the cameras again).
  void UpdateImageCamera(image_t image_id, camera_t camera_id);
  // Deletes the camera (and its housing) when no image has it any more;
  // true if it was deleted.
  bool DeleteCameraIfUnused(camera_t camera_id);
  std::vector<DatabaseImage> ReadAllImages();

  // Replaces the image's keypoints / descriptors.
  void WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints);
  // Reads 6-, 4- (x, y, scale, orientation) and 2-column blobs.
  FeatureKeypoints ReadKeypoints(image_t image_id);
  void WriteDescriptors(image_t image_id, const FeatureDescriptors& descriptors);
  FeatureDescriptors ReadDescriptors(image_t image_id);
  bool ExistsKeypoints(image_t image_id);
  bool ExistsDescriptors(image_t image_id);

  // Matches are stored for (min id, max id); reading swaps back as needed.
  void WriteMatches(image_t image_id1, image_t image_id2, const FeatureMatches& matches);
  FeatureMatches ReadMatches(image_t image_id1, image_t image_id2);
  std::vector<std::pair<image_pair_t, FeatureMatches>> ReadAllMatches();
  void WriteTwoViewGeometry(image_t image_id1, image_t image_id2, const TwoViewGeometry& geometry);
  std::optional<TwoViewGeometry> ReadTwoViewGeometry(image_t image_id1, image_t image_id2);
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> ReadTwoViewGeometries();
  // Pair ids that have a matches row.
  std::vector<image_pair_t> ReadMatchPairIds();
  // Pair ids that have a two_view_geometries row (verified or not).
  std::vector<image_pair_t> ReadTwoViewGeometryPairIds();
  // Each verified pair's number of inlier matches (the rows column), for
  // the pairs with any, without decoding the matches (COLMAP's
  // ReadTwoViewGeometryNumInliers).
  std::vector<std::pair<image_pair_t, int>> ReadTwoViewGeometryNumInliers();
  // Deletes matches and geometries of every pair involving the image.
  void DeleteMatchesOfImage(image_t image_id);
  // Deletes the image and every row about it (features, matches, target
  // observations and status, markers); its camera stays.
  void DeleteImage(image_t image_id);

  int64_t NumCameras();
  int64_t NumImages();
  int64_t NumKeypoints();  // summed over images
  int64_t NumDescriptors();
  int64_t NumMatches();  // summed over pairs
  int64_t NumInlierMatches();
  int64_t NumMatchedImagePairs();
  int64_t NumVerifiedImagePairs();

  // --- portcal tables ------------------------------------------------------
  void WriteHousing(camera_t camera_id, const Housing& housing);
  std::optional<Housing> ReadHousing(camera_t camera_id);
  std::map<camera_t, Housing> ReadAllHousings();

  // Replace the image's rows.
  void WriteTargetObservations(image_t image_id, const std::vector<TargetObservation>& rows);
  std::vector<TargetObservation> ReadTargetObservations(image_t image_id);
  void WriteTargetDetectionStatus(image_t image_id, const TargetDetectionStatus& status);
  std::optional<TargetDetectionStatus> ReadTargetDetectionStatus(image_t image_id);
  void WriteMarkerDetections(image_t image_id, const std::vector<MarkerDetection>& rows);
  std::vector<MarkerDetection> ReadMarkerDetections(image_t image_id);

  // An image's features before feature_masker first masked them.
  void WriteUnmaskedFeatures(image_t image_id, const FeatureKeypoints& keypoints,
                             const FeatureDescriptors& descriptors);
  // False (the outputs untouched) where the image has none.
  bool ReadUnmaskedFeatures(image_t image_id, FeatureKeypoints* keypoints,
                            FeatureDescriptors* descriptors);
  void DeleteUnmaskedFeatures(image_t image_id);
  int64_t NumImagesWithUnmaskedFeatures();

  // Appends a completed run (write it inside the stage's transaction, so a
  // failed stage leaves no log row either).
  int64_t WriteStageLog(const StageLogEntry& entry);
  std::vector<StageLogEntry> ReadStageLog();

  // Converts the database, inside one transaction, to `target`'s layout as
  // that COLMAP's migration would, keeping every row (layout_conversion.cc):
  // pose priors move between images.prior_* and pose_priors, rigs and
  // frames are made one per camera and per image (or dropped where they
  // were that), descriptors gain or lose their type, unset two-view
  // geometry becomes NULL or zeros. Throws InputError, changing nothing,
  // where `target` cannot hold a row (a rig of two cameras, a prior's
  // covariance, ALIKED descriptors in 3.x).
  void ConvertTo(ColmapVersion target);
  // A consistent copy of the whole file at `path` (VACUUM INTO: the
  // write-ahead log that COLMAP 3.9 on leaves included).
  void CopyTo(const std::filesystem::path& path);

 private:
  void CreateSchema(ColmapVersion version);
  void CheckSchema();
  // Rigs and frames (layout().rigs_and_frames): the rig whose sensor the
  // camera is, made (with the camera its reference) when there is none;
  // the new image's frame; the image's frames removed.
  int64_t RigOfCamera(camera_t camera_id);
  void AddFrame(image_t image_id, camera_t camera_id);
  void DeleteFrames(image_t image_id);
  // pose_priors rows (layout().pose_priors != kNone).
  void WritePosePriorRow(image_t image_id, camera_t camera_id, const Eigen::Vector3d& position);
  void DeletePosePriorRows(image_t image_id);
  // layout_conversion.cc's steps, each inside ConvertTo's transaction.
  void ConvertPosePriors(ColmapVersion target);
  void ConvertRigsAndFrames(ColmapVersion target);
  void ConvertDescriptors(const ColmapLayout& target);
  void ConvertTwoViewGeometries(const ColmapLayout& target);
  Statement& Prepare(const std::string& key, const std::string& sql);
  int64_t QueryInt(const std::string& sql);

  std::string path_;
  ColmapLayout layout_;
  std::unique_ptr<LockWait> lock_wait_;  // outlives db_ (declared before it)
  sqlite3* db_ = nullptr;
  std::map<std::string, std::unique_ptr<Statement>> statements_;
};

}  // namespace portcal
