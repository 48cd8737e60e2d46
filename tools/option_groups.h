// Option groups several subcommands share, declared once.
#pragma once

#include "pipelines/images/image_reader.h"
#include "tools/command_line.h"

namespace portcal {

// --ImageReader.camera_model, single_camera, single_camera_per_folder,
// camera_params (COLMAP's names).
inline void AddImageReaderOptions(CommandLine* cli, ImageReaderOptions* reader) {
  cli->Add("ImageReader.camera_model", &reader->camera_model, "COLMAP camera model");
  cli->Add("ImageReader.single_camera", &reader->single_camera, "one camera for all images (0 | 1)");
  cli->Add("ImageReader.single_camera_per_folder", &reader->single_camera_per_folder,
           "one camera per sub-folder, e.g. a stereo rig's cam1/ and cam2/ (0 | 1)");
  cli->Add("ImageReader.camera_params", &reader->camera_params,
           "initial parameters in COLMAP's order (default: from the image size)");
}

}  // namespace portcal
