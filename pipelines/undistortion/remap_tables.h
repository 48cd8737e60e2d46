// Per-pixel remap tables of a virtual pinhole: for each output pixel, the
// real camera's pixel it shows (exact refraction), computed once per
// camera and applied to every image with cv::remap, here or in a robot's
// own code (the tables are written as OpenCV FileStorage).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "colmap_ext/util/progress.h"
#include "pipelines/undistortion/virtual_pinhole.h"

namespace portcal {

struct RemapTables {
  // CV_32FC1 of the output's size: source x and y in OpenCV's convention
  // (integer = pixel centre, i.e. COLMAP's coordinates minus 0.5), -1
  // where the output pixel shows nothing of the image.
  // cv::remap applies these as fast as their fixed-point form
  // (cv::convertMaps; docs/benchmarks.md), so the written tables are the
  // ones portcal applies.
  cv::Mat map_x, map_y;
};

// Exact per pixel, rows on `num_threads` threads; `progress` counts rows.
RemapTables ComputeRemapTables(const VirtualPinhole& pinhole, int num_threads,
                               ProgressSink& progress);

// The undistorted image: bilinear, black where the output shows nothing.
// Throws InputError when `image`'s size is not the tables' camera's.
cv::Mat ApplyRemapTables(const RemapTables& tables, const cv::Mat& image,
                         const cv::Size& source_size);

// FileStorage (YAML; gzip-compressed when `path` ends in .gz): map_x,
// map_y (float32, the output's size), camera_matrix and image_size of the
// virtual pinhole, source_size, design_depth; atomically.
void WriteRemapTables(const RemapTables& tables, const VirtualPinhole& pinhole,
                      const std::filesystem::path& path);

}  // namespace portcal
