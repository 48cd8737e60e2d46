// Appending one database to another, as `colmap database_merger` does:
// the source's cameras and images get new ids after the target's (in the
// source's id order), and every row about them follows with the new ids:
// keypoints, descriptors, matches, two-view geometries, pose priors (their
// positions: a 4.x prior's covariance and gravity are not kept), and
// portcal's housings, target observations and detection status, marker
// detections and unmasked features. The rows are written through
// Database, so they take the target's COLMAP layout (a frame per image in
// its camera's rig: a rig of several sensors is not carried over; the
// descriptors' type, where priors go).
//
// A shard of a distributed stage starts as a copy of the target and adds
// images: MergeOptions::base says which ids the two share, and
// MergeOptions::camera_sharing joins the shards' copies of one shared
// camera, so that the merged database has the rows a single process
// would have written.
#pragma once

#include <map>

#include "database/database.h"

namespace portcal {

struct MergeOptions {
  // Ids up to these are rows the source copied from the target: not
  // appended again; only their per-image rows the target lacks (features
  // extracted in the shard) are added.
  image_t base_image_id = 0;
  camera_t base_camera_id = 0;
  enum class CameraSharing {
    kNone,       // every source camera is a camera of its own
    kAll,        // --ImageReader.single_camera: one shared camera
    kPerFolder,  // --ImageReader.single_camera_per_folder
  };
  // A new source camera equal (model, size, parameters, prior) to a new
  // target camera used in the same folder (any folder, kAll) is that one.
  CameraSharing camera_sharing = CameraSharing::kNone;
};

struct MergeSummary {
  std::map<camera_t, camera_t> cameras;  // source id -> target id
  std::map<image_t, image_t> images;
  int64_t num_pairs = 0;  // match or geometry rows written
};

// Throws InputError naming both files where an image name is in both
// (beyond the base): the merged database would hold it twice.
MergeSummary MergeDatabase(Database* source, Database* target, const MergeOptions& options);

// Every matches and two_view_geometries row of `source` into `target` with
// the same pair ids, replacing the target's rows of those pairs (a shard
// of a distributed matcher, which read the target's images).
void CopyPairRows(Database* source, Database* target);

}  // namespace portcal
