#include "database/database_merge.h"

#include <filesystem>
#include <set>

#include "colmap_ext/util/error.h"

namespace portcal {

namespace {

std::string FolderOf(const std::string& name) {
  return std::filesystem::path(name).parent_path().generic_string();
}

bool SameCamera(const Camera& a, const Camera& b) {
  return a.model_id == b.model_id && a.width == b.width && a.height == b.height &&
         a.params == b.params && a.has_prior_focal_length == b.has_prior_focal_length;
}

// The folder scope each new camera of `database` is shared in ("" for all).
std::map<camera_t, std::set<std::string>> CameraFolders(Database* database, camera_t base,
                                                        MergeOptions::CameraSharing sharing) {
  std::map<camera_t, std::set<std::string>> folders;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    if (image.camera_id <= base) continue;
    folders[image.camera_id].insert(
        sharing == MergeOptions::CameraSharing::kAll ? "" : FolderOf(image.name));
  }
  return folders;
}

void MergeCameras(Database* source, Database* target, const MergeOptions& options,
                  MergeSummary* summary) {
  const camera_t base = options.base_camera_id;
  const auto target_folders = CameraFolders(target, base, options.camera_sharing);
  const auto source_folders = CameraFolders(source, base, options.camera_sharing);
  std::map<camera_t, Camera> target_cameras;
  for (const Camera& camera : target->ReadAllCameras()) target_cameras[camera.camera_id] = camera;
  for (const Camera& camera : source->ReadAllCameras()) {
    if (camera.camera_id <= base) {
      summary->cameras[camera.camera_id] = camera.camera_id;
      continue;
    }
    std::optional<camera_t> shared;
    if (options.camera_sharing != MergeOptions::CameraSharing::kNone &&
        source_folders.count(camera.camera_id)) {
      for (const auto& [id, folders] : target_folders) {
        if (folders == source_folders.at(camera.camera_id) &&
            SameCamera(target_cameras.at(id), camera))
          shared = id;
      }
    }
    summary->cameras[camera.camera_id] = shared ? *shared : target->WriteCamera(camera);
    if (const std::optional<Housing> housing = source->ReadHousing(camera.camera_id);
        housing && !shared) {
      target->WriteHousing(summary->cameras[camera.camera_id], *housing);
    }
  }
}

// The image's rows of portcal's and COLMAP's per-image tables, where the
// target has none of that kind.
void MergeImageRows(Database* source, Database* target, image_t from, image_t to) {
  if (source->ExistsKeypoints(from) && !target->ExistsKeypoints(to)) {
    target->WriteKeypoints(to, source->ReadKeypoints(from));
  }
  if (source->ExistsDescriptors(from) && !target->ExistsDescriptors(to)) {
    target->WriteDescriptors(to, source->ReadDescriptors(from));
  }
  const std::vector<TargetObservation> observations = source->ReadTargetObservations(from);
  if (!observations.empty() && target->ReadTargetObservations(to).empty()) {
    target->WriteTargetObservations(to, observations);
  }
  if (const auto status = source->ReadTargetDetectionStatus(from);
      status && !target->ReadTargetDetectionStatus(to)) {
    target->WriteTargetDetectionStatus(to, *status);
  }
  const std::vector<MarkerDetection> markers = source->ReadMarkerDetections(from);
  if (!markers.empty() && target->ReadMarkerDetections(to).empty())
    target->WriteMarkerDetections(to, markers);
  FeatureKeypoints keypoints;
  FeatureDescriptors descriptors;
  FeatureKeypoints unused_keypoints;
  FeatureDescriptors unused_descriptors;
  if (source->ReadUnmaskedFeatures(from, &keypoints, &descriptors) &&
      !target->ReadUnmaskedFeatures(to, &unused_keypoints, &unused_descriptors)) {
    target->WriteUnmaskedFeatures(to, keypoints, descriptors);
  }
}

void MergeImages(Database* source, Database* target, const MergeOptions& options,
                 MergeSummary* summary) {
  for (const DatabaseImage& image : source->ReadAllImages()) {
    if (image.image_id <= options.base_image_id) {
      summary->images[image.image_id] = image.image_id;
    } else {
      if (target->ReadImageWithName(image.name)) {
        throw InputError(source->path() + ": image '" + image.name + "' is in " + target->path() +
                         " already; a merged database would hold it twice");
      }
      DatabaseImage moved = image;
      moved.camera_id = summary->cameras.at(image.camera_id);
      summary->images[image.image_id] = target->WriteImage(moved);
    }
    MergeImageRows(source, target, image.image_id, summary->images.at(image.image_id));
  }
}

// Matches and geometries of pairs the target has none of.
void MergePairs(Database* source, Database* target, MergeSummary* summary) {
  const std::vector<image_pair_t> match_ids = target->ReadMatchPairIds();
  const std::vector<image_pair_t> geometry_ids = target->ReadTwoViewGeometryPairIds();
  const std::set<image_pair_t> has_matches(match_ids.begin(), match_ids.end());
  const std::set<image_pair_t> has_geometry(geometry_ids.begin(), geometry_ids.end());
  std::set<image_pair_t> written;
  const auto target_pair = [&](image_pair_t pair_id, image_t* a, image_t* b) {
    PairIdToImagePair(pair_id, a, b);
    *a = summary->images.at(*a);
    *b = summary->images.at(*b);
    return ImagePairToPairId(*a, *b);
  };
  for (const auto& [pair_id, matches] : source->ReadAllMatches()) {
    image_t a = 0, b = 0;
    const image_pair_t to = target_pair(pair_id, &a, &b);
    if (has_matches.count(to)) continue;
    target->WriteMatches(a, b, matches);
    written.insert(to);
  }
  for (const auto& [pair_id, geometry] : source->ReadTwoViewGeometries()) {
    image_t a = 0, b = 0;
    const image_pair_t to = target_pair(pair_id, &a, &b);
    if (has_geometry.count(to)) continue;
    target->WriteTwoViewGeometry(a, b, geometry);
    written.insert(to);
  }
  summary->num_pairs = static_cast<int64_t>(written.size());
}

}  // namespace

MergeSummary MergeDatabase(Database* source, Database* target, const MergeOptions& options) {
  MergeSummary summary;
  MergeCameras(source, target, options, &summary);
  MergeImages(source, target, options, &summary);
  MergePairs(source, target, &summary);
  return summary;
}

void CopyPairRows(Database* source, Database* target) {
  image_t a = 0, b = 0;
  for (const auto& [pair_id, matches] : source->ReadAllMatches()) {
    PairIdToImagePair(pair_id, &a, &b);
    target->WriteMatches(a, b, matches);
  }
  for (const auto& [pair_id, geometry] : source->ReadTwoViewGeometries()) {
    PairIdToImagePair(pair_id, &a, &b);
    target->WriteTwoViewGeometry(a, b, geometry);
  }
}

}  // namespace portcal
