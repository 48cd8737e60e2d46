// What incremental structure-from-motion works on: the database's images,
// keypoints and verified correspondences (read once), and the growing
// reconstruction (registered poses, 3-D points and their tracks). Every
// keypoint is also kept as a ray in the camera frame -- in water, starting
// on the port's outer surface, when the camera sits behind a housing -- so
// that registration and triangulation work on refracted rays.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/io/sparse_model.h"
#include "database/database.h"

namespace portcal {

struct Correspondence {
  image_t image_id;
  point2D_t point2D_idx;
};

struct SfmImage {
  image_t image_id = 0;
  std::string name;
  camera_t camera_id = kInvalidCameraId;
  std::vector<Eigen::Vector2d> keypoints;  // COLMAP pixels
  std::vector<float> scales;               // SIFT scale per keypoint (empty: unknown)
  std::vector<std::vector<Correspondence>> correspondences;  // per keypoint
  std::vector<MarkerDetection> markers;
  // Where navigation says the camera centre was (world frame, metres).
  std::optional<Eigen::Vector3d> position_prior;
  int num_correspondences = 0;  // keypoints with at least one
};

// Read-only inputs of the mapper.
struct SfmInputs {
  std::map<camera_t, HousedCamera> cameras;
  std::map<image_t, SfmImage> images;
  // Verified pairs (pair id -> number of inlier matches).
  std::map<image_pair_t, int> pair_inliers;
  // Pairs whose geometry is (nearly) a homography: a plane or a rotation.
  std::set<image_pair_t> planar_pairs;
  // Reads images, cameras, housings (portcal_housings), keypoints, marker
  // detections and the inlier matches of verified pairs; with `only`, only
  // the images of those names and the pairs between them.
  static SfmInputs Read(Database* database, const std::set<std::string>* only = nullptr);
  // From a sparse model: its images' keypoints (no correspondences), its
  // cameras and housings. Marker detections are added separately.
  static SfmInputs FromSparseModel(const SparseModel& model);
};

struct SfmPoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::vector<TrackElement> track;
};

// The centre of the virtual camera that sees `ray` as a central ray: the
// point of the housing's refraction axis closest to it (flat port: the axis
// along the normal; dome: through the sphere's centre), or the camera
// centre without a housing or for a ray along the axis.
Eigen::Vector3d VirtualCenterOf(const HousedCamera& camera, const Ray3d& ray_in_cam);

// One model being grown.
class Reconstruction {
 public:
  // `cameras`: the intrinsics and housings to start from.
  Reconstruction(const SfmInputs* inputs, std::map<camera_t, HousedCamera> cameras);

  const SfmInputs& inputs() const { return *inputs_; }
  bool IsRegistered(image_t image_id) const { return poses_.count(image_id) > 0; }
  const std::map<image_t, Rigid3d>& poses() const { return poses_; }
  std::map<image_t, Rigid3d>& mutable_poses() { return poses_; }
  void Register(image_t image_id, const Rigid3d& cam_from_world);
  void Deregister(image_t image_id);  // drops its observations

  const std::map<point3D_t, SfmPoint>& points() const { return points_; }
  SfmPoint& point(point3D_t id) { return points_.at(id); }
  // The point a keypoint observes, or kInvalidPoint3DId.
  point3D_t PointOf(image_t image_id, point2D_t idx) const;
  point3D_t AddPoint(const Eigen::Vector3d& xyz, const std::vector<TrackElement>& track);
  void AddObservation(point3D_t id, const TrackElement& element);
  void DeleteObservation(image_t image_id, point2D_t idx);  // deletes points left with < 2
  void DeletePoint(point3D_t id);
  // Number of the image's keypoints that observe a point.
  int NumObservations(image_t image_id) const;
  // The points that the images observe, ascending and each once: a local
  // adjustment's points, found through the images' keypoints rather than a
  // walk over every point of the model (which made each registration cost
  // O(model), the mapper O(N^2)).
  std::vector<point3D_t> PointsSeenBy(const std::set<image_t>& image_ids) const;
  // Number of the image's keypoints with a correspondence that observes a
  // point of the model: how many 2-D--3-D links registering it would find
  // (COLMAP's num_visible_points3D). Kept up to date as observations come
  // and go, so ranking the next images costs O(images), not a walk over
  // every unregistered image's correspondences.
  int NumVisiblePoints(image_t image_id) const;

  // Camera and housing of an image (the inputs' unless refined here).
  const HousedCamera& CameraOf(image_t image_id) const;
  std::map<camera_t, HousedCamera>& mutable_cameras() { return cameras_; }
  const std::map<camera_t, HousedCamera>& cameras() const { return cameras_; }

  // The keypoint's ray in the camera frame (nullopt: the pixel has none).
  const std::optional<Ray3d>& RayOf(image_t image_id, point2D_t idx) const {
    return rays_.at(image_id)[idx];
  }
  // Recomputes the rays of every image (after intrinsics or housing changed).
  void UpdateRays();

  // Pixel error of a point seen by a keypoint (infinity where not visible).
  double ReprojectionError(image_t image_id, point2D_t idx, const Eigen::Vector3d& xyz) const;
  // Mean reprojection error over all observations.
  double MeanReprojectionError() const;
  // Deletes the observations whose reprojection error exceeds the limit
  // or cannot be computed (and points left with < 2); returns how many.
  int DeleteObservationsBeyond(double max_error_px);
  // Deletes the observations whose point no longer projects into their
  // image (behind the camera, inside a port's outer surface, totally
  // reflected): a model rescaled or realigned, its points moved, can hold
  // them, and an adjustment cannot start with one. Returns how many.
  int DeleteUnprojectableObservations() {
    return DeleteObservationsBeyond(std::numeric_limits<double>::max());
  }

  SparseModel ToSparseModel() const;
  // The model's poses and points (inputs from SfmInputs::FromSparseModel).
  static Reconstruction FromSparseModel(const SfmInputs* inputs, const SparseModel& model);

 private:
  const SfmInputs* inputs_;
  std::map<camera_t, HousedCamera> cameras_;
  std::map<image_t, Rigid3d> poses_;
  std::map<point3D_t, SfmPoint> points_;
  std::map<image_t, std::vector<point3D_t>> point_of_;
  std::map<image_t, std::vector<std::optional<Ray3d>>> rays_;  // per registered image, per keypoint
  point3D_t next_point_id_ = 1;
  // Per image (all of the inputs'), per keypoint: how many of its
  // correspondences observe a point; and per image, how many of its
  // keypoints have at least one.
  std::unordered_map<image_t, std::vector<int>> num_observing_correspondences_;
  std::unordered_map<image_t, int> num_visible_points_;
  // A keypoint started (+1) or stopped (-1) observing a point.
  void UpdateVisibility(image_t image_id, point2D_t idx, int change);
};

// Puts `housing` in front of every camera (a user's housing for all).
void ReplaceHousings(const Housing& housing, std::map<camera_t, HousedCamera>* cameras);

}  // namespace portcal
