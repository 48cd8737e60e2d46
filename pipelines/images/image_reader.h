// Importing images into the database the way COLMAP's ImageReader does: one
// `images` row per file (name relative to the image directory), cameras per
// --ImageReader.camera_model / single_camera / camera_params.
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "database/database.h"

namespace portcal {

struct ImageReaderOptions {
  std::string camera_model = "SIMPLE_RADIAL";  // COLMAP model name
  bool single_camera = false;                  // one camera for all images
  bool single_camera_per_folder = false;       // one camera per sub-folder (stereo: cam1/, cam2/)
  std::string camera_params;                   // "" = default from the image size
  // Default focal length = factor * max(width, height) (COLMAP's 1.2).
  double default_focal_length_factor = 1.2;
  // A rerun meets images the database already holds: where their cameras
  // differ from these options (model, one camera per image / folder / all),
  // true imports the cameras again (the images keep their ids and data;
  // cameras no image has any more are deleted), false is an error naming
  // the difference.
  bool overwrite = false;
  void Check() const;  // throws OptionError naming --ImageReader.*
};

// Image files (.png .jpg .jpeg .tif .tiff .bmp, any case) below `dir`,
// sorted, as paths relative to `dir`. Throws InputError if there are none.
std::vector<std::string> ListImages(const std::filesystem::path& dir);

// Images with a side under this many pixels hold neither a target nor SIFT
// features worth the name (OpenCV's adaptive threshold asserts on them): a
// stage skips them, like unreadable files, with a warning naming them.
constexpr int kMinImageSide = 16;
// "" for an image of usable size, else why it is skipped.
std::string ImageSizeProblem(int width, int height);

// The cameras of one import: shared between images (single_camera, or per
// folder), and every camera an image was given.
struct SharedCameras {
  std::map<std::string, camera_t> by_folder;  // "" with single_camera
  std::set<camera_t> given;
};

// Adds (or finds, on a rerun) the image and its camera. Call inside the
// stage's transaction. Throws InputError naming the image when its size does
// not match its shared or existing camera, and, without options.overwrite,
// when the image is in the database with a camera other than the options
// would give it (another model, or shared otherwise).
image_t ImportImage(Database* database, const ImageReaderOptions& options, const std::string& name,
                    int width, int height, SharedCameras* shared);

}  // namespace portcal
