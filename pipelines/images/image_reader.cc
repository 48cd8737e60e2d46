#include "pipelines/images/image_reader.h"

#include <algorithm>
#include <cctype>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/image_name.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"

namespace fs = std::filesystem;

namespace portcal {

void ImageReaderOptions::Check() const {
  if (!ExistsCameraModelWithName(camera_model)) {
    throw OptionError("--ImageReader.camera_model", camera_model, "one of " + CameraModelNames());
  }
  if (!camera_params.empty()) {
    const std::vector<double> params =
        ParseDoubleList(camera_params, "--ImageReader.camera_params");
    const int expected = CameraModelNumParams(CameraModelNameToId(camera_model));
    if (static_cast<int>(params.size()) != expected) {
      throw OptionError("--ImageReader.camera_params", camera_params,
                        std::to_string(expected) + " numbers (" +
                            CameraModelParamsInfo(CameraModelNameToId(camera_model)) + ")");
    }
  }
  if (!(default_focal_length_factor > 0)) {
    throw OptionError("--ImageReader.default_focal_length_factor", default_focal_length_factor,
                      "> 0");
  }
}

std::string ImageSizeProblem(int width, int height) {
  if (width >= kMinImageSide && height >= kMinImageSide) return "";
  return std::to_string(width) + "x" + std::to_string(height) + " pixels, under " +
         std::to_string(kMinImageSide) + " a side";
}

std::vector<std::string> ListImages(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a directory of images");
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff" ||
        ext == ".bmp") {
      // Lexically: a symlinked image keeps its link's name (fs::relative would
      // resolve the link and name the target's path).
      std::string name = entry.path().lexically_relative(dir).generic_string();
      const std::string problem = ImageNameProblem(name);
      if (!problem.empty()) {
        LOG(WARNING) << dir.string() << ": skipping image '" << ShownImageName(name)
                     << "', whose name " << problem;
        continue;
      }
      names.push_back(std::move(name));
    }
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) throw InputError(dir.string() + ": no images (.png, .jpg, .tif, .bmp)");
  return names;
}

namespace {

Camera NewCamera(const ImageReaderOptions& options, int width, int height) {
  Camera camera = Camera::FromModelName(
      options.camera_model, options.default_focal_length_factor * std::max(width, height), width,
      height);
  if (!options.camera_params.empty()) {
    camera.params = ParseDoubleList(options.camera_params, "--ImageReader.camera_params");
    camera.has_prior_focal_length = true;
  }
  return camera;
}

// How the existing image's camera differs from what the options would give
// it in this import, or "" where it does not.
std::string ImportDifference(const Camera& camera, const ImageReaderOptions& options,
                             const std::string& folder, const SharedCameras& shared) {
  if (camera.ModelName() != options.camera_model) {
    return "its camera is " + camera.ModelName() + ", --ImageReader.camera_model asks for " +
           options.camera_model;
  }
  const bool sharing = options.single_camera || options.single_camera_per_folder;
  const auto it = shared.by_folder.find(folder);
  if (sharing && it != shared.by_folder.end() && it->second != camera.camera_id) {
    return std::string("it has a camera of its own, --ImageReader.single_camera") +
           (options.single_camera ? "" : "_per_folder") + " asks for one shared camera";
  }
  if (!sharing && shared.given.count(camera.camera_id)) {
    return "it shares camera " + std::to_string(camera.camera_id) +
           " with another image, the options ask for one camera per image "
           "(--ImageReader.single_camera 0)";
  }
  return "";
}

// The camera an image the database already holds in `folder` (anywhere
// with single_camera) has, where it is what the options ask for and of the
// new image's size: a new image of a rerun joins it. Images of another
// camera (in a database COLMAP or another import filled) keep theirs.
std::optional<camera_t> ExistingSharedCamera(Database* database, const ImageReaderOptions& options,
                                             const std::string& folder, int width, int height) {
  for (const DatabaseImage& image : database->ReadAllImages()) {
    if (!options.single_camera && fs::path(image.name).parent_path().generic_string() != folder)
      continue;
    const std::optional<Camera> camera = database->ReadCamera(image.camera_id);
    if (camera && camera->ModelName() == options.camera_model &&
        camera->width == static_cast<uint64_t>(width) &&
        camera->height == static_cast<uint64_t>(height)) {
      return image.camera_id;
    }
  }
  return std::nullopt;
}

// The camera a new (or re-imported) image gets: its folder's shared one, or
// a new one.
camera_t CameraForImport(Database* database, const ImageReaderOptions& options,
                         const std::string& name, const std::string& folder, int width, int height,
                         SharedCameras* shared) {
  const bool sharing = options.single_camera || options.single_camera_per_folder;
  if (sharing && !shared->by_folder.count(folder) && !options.overwrite) {
    if (const std::optional<camera_t> existing =
            ExistingSharedCamera(database, options, folder, width, height)) {
      shared->by_folder.emplace(folder, *existing);
    }
  }
  if (sharing && shared->by_folder.count(folder)) {
    const camera_t camera_id = shared->by_folder.at(folder);
    const std::optional<Camera> camera = database->ReadCamera(camera_id);
    if (camera && (camera->width != static_cast<uint64_t>(width) ||
                   camera->height != static_cast<uint64_t>(height))) {
      throw InputError(name + ": " + std::to_string(width) + "x" + std::to_string(height) +
                       " pixels, but it shares a " + std::to_string(camera->width) + "x" +
                       std::to_string(camera->height) + " camera (--ImageReader.single_camera" +
                       (options.single_camera ? "" : "_per_folder") + ")");
    }
    return camera_id;
  }
  const camera_t camera_id = database->WriteCamera(NewCamera(options, width, height));
  if (sharing) shared->by_folder.emplace(folder, camera_id);
  return camera_id;
}

}  // namespace

image_t ImportImage(Database* database, const ImageReaderOptions& options, const std::string& name,
                    int width, int height, SharedCameras* shared) {
  const bool sharing = options.single_camera || options.single_camera_per_folder;
  const std::string folder =
      options.single_camera ? std::string() : fs::path(name).parent_path().generic_string();
  if (const std::optional<DatabaseImage> existing = database->ReadImageWithName(name)) {
    const std::optional<Camera> camera = database->ReadCamera(existing->camera_id);
    if (camera && (camera->width != static_cast<uint64_t>(width) ||
                   camera->height != static_cast<uint64_t>(height))) {
      throw InputError(name + ": " + std::to_string(width) + "x" + std::to_string(height) +
                       " pixels, but its camera in the database is " +
                       std::to_string(camera->width) + "x" + std::to_string(camera->height));
    }
    const std::string difference =
        camera ? ImportDifference(*camera, options, folder, *shared) : "";
    if (difference.empty()) {
      if (sharing) shared->by_folder.emplace(folder, existing->camera_id);
      shared->given.insert(existing->camera_id);
      return existing->image_id;
    }
    if (!options.overwrite) {
      throw InputError(name + ": imported before, and " + difference +
                       "; rerun with --ImageReader.overwrite 1 to import its camera again, or use "
                       "a new database");
    }
    const camera_t camera_id =
        CameraForImport(database, options, name, folder, width, height, shared);
    database->UpdateImageCamera(existing->image_id, camera_id);
    database->DeleteCameraIfUnused(existing->camera_id);
    shared->given.insert(camera_id);
    return existing->image_id;
  }
  DatabaseImage image;
  image.name = name;
  image.camera_id = CameraForImport(database, options, name, folder, width, height, shared);
  shared->given.insert(image.camera_id);
  return database->WriteImage(image);
}

}  // namespace portcal
