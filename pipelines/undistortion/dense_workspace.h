// A COLMAP dense workspace as `colmap image_undistorter` lays it out:
// images/ (written by the caller), sparse/ (the pinhole model, binary),
// stereo/ (patch-match.cfg, fusion.cfg, the empty depth_maps,
// normal_maps and consistency_graphs folders) and the two run-colmap-*.sh
// scripts, so `colmap patch_match_stereo --workspace_path OUT` and the tools
// that read such workspaces take it as it is.
#pragma once

#include <filesystem>
#include <map>

#include "colmap_ext/io/sparse_model.h"
#include "pipelines/undistortion/virtual_pinhole.h"

namespace portcal {

// `model` seen by the virtual pinholes: PINHOLE cameras, poses rotated into
// the pinholes' frames (identity but for rectified pairs), each keypoint
// where the undistorted image shows it (as COLMAP's undistorter, also
// outside the output image; one without a ray leaves its point's track),
// points kept while they have a track, no housings.
SparseModel PinholeModel(const SparseModel& model,
                         const std::map<camera_t, VirtualPinhole>& pinholes);

// sparse/, stereo/ and the scripts into `dir` (which exists).
void WriteDenseWorkspace(const SparseModel& pinhole_model, const std::filesystem::path& dir);

}  // namespace portcal
