#include "pipelines/undistortion/dense_workspace.h"

#include <Eigen/Geometry>
#include <sstream>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

void WriteText(const fs::path& path, const std::string& text) {
  WriteFileAtomically(path, false, [&](std::ostream& out) { out << text; });
}

// The scripts `colmap image_undistorter` leaves beside a workspace, for
// `colmap` on the PATH.
std::string RunScript(bool geometric) {
  std::ostringstream out;
  out << "#!/usr/bin/env bash\n"
      << "# Dense reconstruction of this workspace with stock COLMAP (`colmap` on the PATH).\n"
      << "set -euo pipefail\ncd \"$(dirname \"$0\")\"\n"
      << "colmap patch_match_stereo --workspace_path . --workspace_format COLMAP"
      << " --PatchMatchStereo.max_image_size 2000 --PatchMatchStereo.geom_consistency "
      << (geometric ? "true" : "false") << "\n"
      << "colmap stereo_fusion --workspace_path . --workspace_format COLMAP --input_type "
      << (geometric ? "geometric" : "photometric") << " --output_path ./fused.ply\n"
      << "colmap poisson_mesher --input_path ./fused.ply --output_path ./meshed-poisson.ply\n"
      << "colmap delaunay_mesher --input_path . --input_type dense --output_path "
         "./meshed-delaunay.ply\n";
  return out.str();
}

}  // namespace

SparseModel PinholeModel(const SparseModel& model,
                         const std::map<camera_t, VirtualPinhole>& pinholes) {
  SparseModel result;
  for (const auto& [camera_id, camera] : model.cameras) {
    const auto it = pinholes.find(camera_id);
    PORTCAL_CHECK(it != pinholes.end());
    result.cameras[camera_id] = it->second.pinhole;
  }
  result.points3D = model.points3D;
  for (auto& [point_id, point] : result.points3D) point.track.clear();
  for (const auto& [image_id, image] : model.images) {
    const VirtualPinhole& pinhole = pinholes.at(image.camera_id);
    Image mapped = image;
    const Eigen::Quaterniond rotation(pinhole.pinhole_from_cam);
    mapped.cam_from_world = Rigid3d(rotation, Eigen::Vector3d::Zero()) * image.cam_from_world;
    for (size_t i = 0; i < mapped.points2D.size(); ++i) {
      Point2D& point2D = mapped.points2D[i];
      const std::optional<Eigen::Vector2d> output = pinhole.OutputPixel(point2D.xy);
      if (output) point2D.xy = *output;
      const auto point = result.points3D.find(point2D.point3D_id);
      if (!output || point == result.points3D.end()) {
        point2D.point3D_id = kInvalidPoint3DId;
        continue;
      }
      point->second.track.push_back({image_id, static_cast<point2D_t>(i)});
    }
    result.images[image_id] = std::move(mapped);
  }
  for (auto it = result.points3D.begin(); it != result.points3D.end();) {
    it = it->second.track.empty() ? result.points3D.erase(it) : std::next(it);
  }
  return result;
}

void WriteDenseWorkspace(const SparseModel& pinhole_model, const fs::path& dir) {
  WriteSparseModel(pinhole_model, dir / "sparse", ModelFormat::kBinary);
  for (const char* folder : {"depth_maps", "normal_maps", "consistency_graphs"}) {
    fs::create_directories(dir / "stereo" / folder);
  }
  std::string patch_match, fusion;
  for (const auto& [image_id, image] : pinhole_model.images) {
    // COLMAP's default: the 20 images that share the most points.
    patch_match += image.name + "\n__auto__, 20\n";
    fusion += image.name + "\n";
    const fs::path parent = fs::path(image.name).parent_path();
    if (!parent.empty()) {
      for (const char* folder : {"depth_maps", "normal_maps", "consistency_graphs"}) {
        fs::create_directories(dir / "stereo" / folder / parent);
      }
    }
  }
  WriteText(dir / "stereo" / "patch-match.cfg", patch_match);
  WriteText(dir / "stereo" / "fusion.cfg", fusion);
  WriteText(dir / "run-colmap-geometric.sh", RunScript(true));
  WriteText(dir / "run-colmap-photometric.sh", RunScript(false));
}

}  // namespace portcal
