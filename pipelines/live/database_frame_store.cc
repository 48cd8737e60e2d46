#include "pipelines/live/database_frame_store.h"

#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "colmap_ext/util/confined_path.h"
#include "colmap_ext/util/error.h"
#include "pipelines/detection/detection_rows.h"

namespace fs = std::filesystem;

namespace portcal {

DatabaseFrameStore::DatabaseFrameStore(Database* database, std::string image_path,
                                       const TargetDetectorOptions& detector,
                                       std::vector<std::string> folders,
                                       std::vector<ImageReaderOptions> readers)
    : database_(database),
      image_path_(std::move(image_path)),
      target_(TargetDescriptionText(detector)),
      readers_(std::move(readers)),
      folders_(std::move(folders)) {
  const bool stereo = folders_.size() > 1;
  for (ImageReaderOptions& reader : readers_) {
    reader.single_camera = !stereo;
    reader.single_camera_per_folder = stereo;
  }
  // A continued session: the new frames join the camera of the kept ones
  // (a frame of another size is then refused, naming both).
  std::set<camera_t> cameras;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    cameras.insert(image.camera_id);
    CheckContinues(image);
  }
  if (!stereo && cameras.size() == 1) shared_.by_folder[""] = *cameras.begin();
}

void DatabaseFrameStore::CheckContinues(const DatabaseImage& image) const {
  // Only the views count: a database may hold other images too.
  const std::optional<TargetDetectionStatus> status =
      database_->ReadTargetDetectionStatus(image.image_id);
  if (!status || !status->found) return;
  if (status->target != target_) {
    throw InputError(database_->path() + ": its views (" + image.name + ") are of the target '" +
                     status->target + "', the --Target.* options describe '" + target_ +
                     "'; continue with the same board, or give another --database_path");
  }
  const std::optional<Camera> camera = database_->ReadCamera(image.camera_id);
  size_t c = 0;  // the camera whose folder holds the image (a rig's cam2/)
  while (c + 1 < folders_.size() && image.name.rfind(folders_[c] + "/", 0) != 0) ++c;
  const std::string& asked = readers_[c].camera_model;
  if (camera && camera->ModelName() != asked) {
    throw InputError(database_->path() + ": its views (" + image.name + ") are of a " +
                     camera->ModelName() + " camera, this session's is " + asked +
                     " (--ImageReader.camera_model or --input_calibration); continue with the "
                     "same model, or give "
                     "another --database_path");
  }
}

std::string DatabaseFrameStore::Store(const std::vector<cv::Mat>& images,
                                      const std::vector<TargetDetection>& detections) {
  const std::string name = NextName();
  std::vector<fs::path> written;
  try {
    for (size_t c = 0; c < images.size(); ++c)
      written.push_back(WriteFrame(images[c], ImageName(c, name)));
    Transaction transaction = database_->BeginTransaction();
    for (size_t c = 0; c < images.size(); ++c) {
      const image_t id = ImportImage(database_, readers_[c], ImageName(c, name), images[c].cols,
                                     images[c].rows, &shared_);
      WriteTargetDetection(database_, id, detections[c], target_);
    }
    transaction.Commit();
  } catch (...) {
    std::error_code ignored;
    for (const fs::path& path : written) fs::remove(path, ignored);
    throw;
  }
  return name;
}

void DatabaseFrameStore::Remove(const std::string& name) {
  Transaction transaction = database_->BeginTransaction();
  for (size_t c = 0; c < folders_.size(); ++c) {
    // The file renamed below must be one inside --image_path.
    ConfinedPath(image_path_, ImageName(c, name), "image name in " + database_->path());
    const std::optional<DatabaseImage> image = database_->ReadImageWithName(ImageName(c, name));
    if (!image) throw InputError(ImageName(c, name) + ": not in " + database_->path());
    database_->DeleteImage(image->image_id);
  }
  transaction.Commit();
  for (size_t c = 0; c < folders_.size(); ++c) {
    const fs::path path = fs::path(image_path_) / ImageName(c, name);
    std::error_code ignored;
    fs::rename(path, fs::path(path.string() + ".removed"), ignored);
  }
}

std::vector<int> DatabaseFrameStore::camera_ids() const {
  std::vector<int> ids;
  for (const std::string& folder : folders_) {
    const auto it = shared_.by_folder.find(folder);
    ids.push_back(it == shared_.by_folder.end() ? -1 : static_cast<int>(it->second));
  }
  return ids;
}

std::string DatabaseFrameStore::ImageName(size_t camera, const std::string& name) const {
  return folders_[camera].empty() ? name : folders_[camera] + "/" + name;
}

fs::path DatabaseFrameStore::WriteFrame(const cv::Mat& image, const std::string& name) const {
  const fs::path path = fs::path(image_path_) / name;
  const fs::path partial = path.parent_path() / ("." + path.filename().string() + ".partial.png");
  std::error_code error;
  // At the first keep: a session that keeps nothing leaves nothing.
  fs::create_directories(path.parent_path(), error);
  bool written = false;
  if (!error) {
    try {
      written = cv::imwrite(partial.string(), image);
    } catch (const cv::Exception&) {
      written = false;  // libpng's write error, as OpenCV reports it
    }
  }
  if (!written) {
    fs::remove(partial, error);
    throw FrameStoreBroken(partial.string() + ": cannot write a kept frame (" +
                           (error ? error.message() : "a full disk or a read-only folder?") +
                           "); " + Kept() + " stay in " + database_->path() + " and " +
                           image_path_);
  }
  fs::rename(partial, path, error);
  if (error) {
    throw FrameStoreBroken(path.string() + ": cannot move a kept frame into place (" +
                           error.message() + "); " + Kept() + " stay in " + database_->path() +
                           " and " + image_path_);
  }
  return path;
}

std::string DatabaseFrameStore::Kept() const {
  return std::to_string(database_->NumImages()) + " images kept before";
}

std::string DatabaseFrameStore::NextName() {
  while (true) {
    std::ostringstream name;
    name << "live_" << std::setw(4) << std::setfill('0') << ++counter_ << ".png";
    bool taken = false;
    for (size_t c = 0; c < folders_.size(); ++c) {
      const fs::path path = fs::path(image_path_) / ImageName(c, name.str());
      taken = taken || fs::exists(path) || fs::exists(path.string() + ".removed") ||
              database_->ReadImageWithName(ImageName(c, name.str()));
    }
    if (!taken) return name.str();
  }
}

std::vector<KeptView> ExistingViews(Database* database, const std::vector<std::string>& folders) {
  std::map<std::string, KeptView> by_name;
  for (const DatabaseImage& image : database->ReadAllImages()) {
    const fs::path path(image.name);
    const bool stereo = folders.size() > 1;
    const auto folder =
        std::find(folders.begin(), folders.end(), path.parent_path().generic_string());
    if (stereo && folder == folders.end()) continue;
    const bool second = stereo && folder != folders.begin();
    const std::string name = stereo ? path.filename().string() : image.name;
    KeptView& view = by_name[name];
    view.name = name;
    CalibrationView& calibration_view = second ? view.view2 : view.view;
    calibration_view.image_name = view.name;
    for (const TargetObservation& o : database->ReadTargetObservations(image.image_id)) {
      calibration_view.points_in_target.push_back(o.point_in_target);
      calibration_view.pixels.push_back(o.xy);
      (second ? view.corners2 : view.corners)[static_cast<int>(o.point_id)] = o.xy;
    }
  }
  std::vector<KeptView> kept;
  for (auto& [name, view] : by_name) {
    const bool complete =
        !view.view.pixels.empty() && (folders.size() == 1 || !view.view2.pixels.empty());
    if (complete) kept.push_back(std::move(view));
  }
  return kept;
}

}  // namespace portcal
