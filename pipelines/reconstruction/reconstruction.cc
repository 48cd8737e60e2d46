#include "pipelines/reconstruction/reconstruction.h"

#include <algorithm>
#include <limits>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"

namespace portcal {

SfmInputs SfmInputs::Read(Database* database, const std::set<std::string>* only) {
  SfmInputs inputs;
  const std::map<camera_t, Housing> housings = database->ReadAllHousings();
  for (const Camera& camera : database->ReadAllCameras()) {
    HousedCamera& c = inputs.cameras[camera.camera_id];
    c.camera = camera;
    const auto it = housings.find(camera.camera_id);
    if (it != housings.end()) c.housing = it->second;
  }
  for (const DatabaseImage& row : database->ReadAllImages()) {
    if (only && !only->count(row.name)) continue;
    if (!inputs.cameras.count(row.camera_id)) {
      throw InputError(database->path() + ": image '" + row.name + "' has camera " +
                       std::to_string(row.camera_id) + ", which the cameras table does not hold");
    }
    SfmImage& image = inputs.images[row.image_id];
    image.image_id = row.image_id;
    image.name = row.name;
    image.camera_id = row.camera_id;
    for (const FeatureKeypoint& k : database->ReadKeypoints(row.image_id)) {
      image.keypoints.emplace_back(k.x, k.y);
      image.scales.push_back(k.ComputeScale());
    }
    image.correspondences.resize(image.keypoints.size());
    image.markers = database->ReadMarkerDetections(row.image_id);
    image.position_prior = row.PriorPosition();
  }
  for (const auto& [pair_id, geometry] : database->ReadTwoViewGeometries()) {
    if (geometry.inlier_matches.empty()) continue;
    image_t id1, id2;
    PairIdToImagePair(pair_id, &id1, &id2);
    if (only && (!inputs.images.count(id1) || !inputs.images.count(id2)))
      continue;  // outside the subset
    if (!inputs.images.count(id1) || !inputs.images.count(id2)) {
      throw InputError(database->path() + ": two_view_geometries of " +
                       database->PairLabel(pair_id) +
                       " names an image the images table does not hold");
    }
    SfmImage& image1 = inputs.images.at(id1);
    SfmImage& image2 = inputs.images.at(id2);
    for (const FeatureMatch& m : geometry.inlier_matches) {
      if (m.point2D_idx1 >= image1.keypoints.size() || m.point2D_idx2 >= image2.keypoints.size()) {
        throw InputError(database->path() + ": inlier match of images '" + image1.name + "' and '" +
                         image2.name +
                         "' names a keypoint that does not exist (features changed "
                         "after matching? rerun the matcher)");
      }
      image1.correspondences[m.point2D_idx1].push_back({id2, m.point2D_idx2});
      image2.correspondences[m.point2D_idx2].push_back({id1, m.point2D_idx1});
    }
    inputs.pair_inliers[pair_id] = static_cast<int>(geometry.inlier_matches.size());
    if (geometry.config == TwoViewGeometryConfig::kPlanar ||
        geometry.config == TwoViewGeometryConfig::kPanoramic ||
        geometry.config == TwoViewGeometryConfig::kPlanarOrPanoramic) {
      inputs.planar_pairs.insert(pair_id);
    }
  }
  for (auto& [id, image] : inputs.images) {
    for (const auto& c : image.correspondences) image.num_correspondences += !c.empty();
  }
  return inputs;
}

SfmInputs SfmInputs::FromSparseModel(const SparseModel& model) {
  SfmInputs inputs;
  for (const auto& [id, camera] : model.cameras) {
    inputs.cameras[id].camera = camera;
    const auto it = model.housings.find(id);
    if (it != model.housings.end()) inputs.cameras[id].housing = it->second;
  }
  for (const auto& [id, image] : model.images) {
    SfmImage& sfm = inputs.images[id];
    sfm.image_id = id;
    sfm.name = image.name;
    sfm.camera_id = image.camera_id;
    for (const Point2D& p : image.points2D) sfm.keypoints.push_back(p.xy);
    sfm.correspondences.resize(sfm.keypoints.size());
  }
  return inputs;
}

Reconstruction Reconstruction::FromSparseModel(const SfmInputs* inputs, const SparseModel& model) {
  Reconstruction r(inputs, inputs->cameras);
  for (const auto& [id, image] : model.images) r.Register(id, image.cam_from_world);
  for (const auto& [id, point] : model.points3D) {
    if (point.track.size() < 2) continue;
    const point3D_t new_id = r.AddPoint(point.xyz, {});
    for (const TrackElement& e : point.track) {
      if (r.PointOf(e.image_id, e.point2D_idx) == kInvalidPoint3DId) r.AddObservation(new_id, e);
    }
    if (r.points().at(new_id).track.size() < 2) r.DeletePoint(new_id);
  }
  return r;
}

Eigen::Vector3d VirtualCenterOf(const HousedCamera& camera, const Ray3d& ray) {
  if (!camera.housing) return Eigen::Vector3d::Zero();
  const std::vector<double>& p = camera.housing->params;
  Eigen::Vector3d axis(p[0], p[1], p[2]);
  if (!(axis.norm() > 1e-12)) return Eigen::Vector3d::Zero();  // concentric dome
  axis.normalize();
  const Eigen::Vector3d d = ray.direction.normalized();
  const double c = axis.dot(d);
  const double sin2 = 1.0 - c * c;
  if (sin2 < 1e-12) return Eigen::Vector3d::Zero();
  return ((axis.dot(ray.origin) - c * d.dot(ray.origin)) / sin2) * axis;
}

Reconstruction::Reconstruction(const SfmInputs* inputs, std::map<camera_t, HousedCamera> cameras)
    : inputs_(inputs), cameras_(std::move(cameras)) {
  for (const auto& [id, image] : inputs_->images) {
    num_observing_correspondences_[id].assign(image.keypoints.size(), 0);
    num_visible_points_[id] = 0;
  }
  UpdateRays();
}

void Reconstruction::UpdateVisibility(image_t image_id, point2D_t idx, int change) {
  for (const Correspondence& c : inputs_->images.at(image_id).correspondences[idx]) {
    int& count = num_observing_correspondences_.at(c.image_id)[c.point2D_idx];
    if (change > 0 && count++ == 0) ++num_visible_points_.at(c.image_id);
    if (change < 0 && --count == 0) --num_visible_points_.at(c.image_id);
  }
}

int Reconstruction::NumVisiblePoints(image_t image_id) const {
  return num_visible_points_.at(image_id);
}

void Reconstruction::UpdateRays() {
  std::vector<const SfmImage*> images;
  for (const auto& [id, image] : inputs_->images) {
    images.push_back(&image);
    rays_[id].assign(image.keypoints.size(), std::nullopt);
  }
  ParallelFor(images.size(), 2, [&](size_t i) {
    const SfmImage& image = *images[i];
    const HousedCamera& camera = cameras_.at(image.camera_id);
    std::vector<std::optional<Ray3d>>& rays = rays_.at(image.image_id);
    for (size_t k = 0; k < image.keypoints.size(); ++k) {
      rays[k] = camera.Unproject(image.keypoints[k]);
    }
  });
}

void Reconstruction::Register(image_t image_id, const Rigid3d& cam_from_world) {
  poses_[image_id] = cam_from_world;
  point_of_[image_id].assign(inputs_->images.at(image_id).keypoints.size(), kInvalidPoint3DId);
}

void Reconstruction::Deregister(image_t image_id) {
  const auto it = point_of_.find(image_id);
  if (it == point_of_.end()) return;
  for (point2D_t k = 0; k < it->second.size(); ++k) {
    if (it->second[k] != kInvalidPoint3DId) DeleteObservation(image_id, k);
  }
  point_of_.erase(image_id);
  poses_.erase(image_id);
}

point3D_t Reconstruction::PointOf(image_t image_id, point2D_t idx) const {
  const auto it = point_of_.find(image_id);
  return it == point_of_.end() ? kInvalidPoint3DId : it->second[idx];
}

point3D_t Reconstruction::AddPoint(const Eigen::Vector3d& xyz,
                                   const std::vector<TrackElement>& track) {
  const point3D_t id = next_point_id_++;
  SfmPoint& point = points_[id];
  point.xyz = xyz;
  for (const TrackElement& e : track) AddObservation(id, e);
  return id;
}

void Reconstruction::AddObservation(point3D_t id, const TrackElement& element) {
  point3D_t& slot = point_of_.at(element.image_id).at(element.point2D_idx);
  PORTCAL_CHECK(slot == kInvalidPoint3DId);
  slot = id;
  points_.at(id).track.push_back(element);
  UpdateVisibility(element.image_id, element.point2D_idx, +1);
}

void Reconstruction::DeleteObservation(image_t image_id, point2D_t idx) {
  point3D_t& slot = point_of_.at(image_id).at(idx);
  if (slot == kInvalidPoint3DId) return;
  const point3D_t id = slot;
  slot = kInvalidPoint3DId;
  UpdateVisibility(image_id, idx, -1);
  SfmPoint& point = points_.at(id);
  for (size_t t = 0; t < point.track.size(); ++t) {
    if (point.track[t].image_id == image_id && point.track[t].point2D_idx == idx) {
      point.track.erase(point.track.begin() + static_cast<std::ptrdiff_t>(t));
      break;
    }
  }
  if (point.track.size() < 2) DeletePoint(id);
}

void Reconstruction::DeletePoint(point3D_t id) {
  const auto it = points_.find(id);
  if (it == points_.end()) return;
  for (const TrackElement& e : it->second.track) {
    point_of_.at(e.image_id).at(e.point2D_idx) = kInvalidPoint3DId;
    UpdateVisibility(e.image_id, e.point2D_idx, -1);
  }
  points_.erase(it);
}

std::vector<point3D_t> Reconstruction::PointsSeenBy(const std::set<image_t>& image_ids) const {
  std::vector<point3D_t> ids;
  for (const image_t image_id : image_ids) {
    const auto it = point_of_.find(image_id);
    if (it == point_of_.end()) continue;
    for (const point3D_t id : it->second) {
      if (id != kInvalidPoint3DId) ids.push_back(id);
    }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

int Reconstruction::NumObservations(image_t image_id) const {
  const auto it = point_of_.find(image_id);
  if (it == point_of_.end()) return 0;
  int n = 0;
  for (point3D_t id : it->second) n += id != kInvalidPoint3DId;
  return n;
}

const HousedCamera& Reconstruction::CameraOf(image_t image_id) const {
  return cameras_.at(inputs_->images.at(image_id).camera_id);
}

double Reconstruction::ReprojectionError(image_t image_id, point2D_t idx,
                                         const Eigen::Vector3d& xyz) const {
  const HousedCamera& camera = CameraOf(image_id);
  const Eigen::Vector3d in_cam = poses_.at(image_id) * xyz;
  const auto pixel = camera.Project(in_cam);
  if (!pixel) return std::numeric_limits<double>::infinity();
  return (*pixel - inputs_->images.at(image_id).keypoints[idx]).norm();
}

double Reconstruction::MeanReprojectionError() const {
  double sum = 0;
  int64_t n = 0;
  for (const auto& [id, point] : points_) {
    for (const TrackElement& e : point.track) {
      sum += ReprojectionError(e.image_id, e.point2D_idx, point.xyz);
      ++n;
    }
  }
  return n ? sum / n : 0.0;
}

int Reconstruction::DeleteObservationsBeyond(double max_error_px) {
  std::vector<std::pair<image_t, point2D_t>> beyond;
  for (const auto& [id, point] : points_) {
    for (const TrackElement& e : point.track) {
      if (!(ReprojectionError(e.image_id, e.point2D_idx, point.xyz) <= max_error_px)) {
        beyond.emplace_back(e.image_id, e.point2D_idx);
      }
    }
  }
  for (const auto& [image_id, idx] : beyond) DeleteObservation(image_id, idx);
  return static_cast<int>(beyond.size());
}

SparseModel Reconstruction::ToSparseModel() const {
  SparseModel model;
  std::map<camera_t, bool> used;
  for (const auto& [image_id, pose] : poses_) {
    const SfmImage& input = inputs_->images.at(image_id);
    Image& image = model.images[image_id];
    image.image_id = image_id;
    image.name = input.name;
    image.camera_id = input.camera_id;
    image.cam_from_world = pose;
    const std::vector<point3D_t>& ids = point_of_.at(image_id);
    for (size_t k = 0; k < input.keypoints.size(); ++k) {
      Point2D p;
      p.xy = input.keypoints[k];
      p.point3D_id = ids[k];
      image.points2D.push_back(p);
    }
    used[input.camera_id] = true;
  }
  for (const auto& [camera_id, camera] : cameras_) {
    if (!used.count(camera_id)) continue;
    model.cameras[camera_id] = camera.camera;
    if (camera.housing) model.housings[camera_id] = *camera.housing;
  }
  for (const auto& [id, point] : points_) {
    Point3D& p = model.points3D[id];
    p.xyz = point.xyz;
    p.color.setConstant(128);
    p.track = point.track;
    double sum = 0;
    for (const TrackElement& e : point.track)
      sum += ReprojectionError(e.image_id, e.point2D_idx, point.xyz);
    p.error = point.track.empty() ? 0.0 : sum / point.track.size();
  }
  return model;
}

void ReplaceHousings(const Housing& housing, std::map<camera_t, HousedCamera>* cameras) {
  for (auto& [id, camera] : *cameras) camera.housing = housing;
}

}  // namespace portcal
