#include "pipelines/undistortion/undistortion_report.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <sstream>

#include "colmap_ext/util/string_utils.h"
#include "pipelines/report/picture.h"

namespace portcal {
namespace {

std::string CameraName(const CameraUndistortion& camera) {
  return "camera " + std::to_string(camera.pinhole.pinhole.camera_id);
}

std::string PinholeLine(const Camera& pinhole) {
  std::string line =
      "PINHOLE " + std::to_string(pinhole.width) + " x " + std::to_string(pinhole.height) + " px,";
  for (const double p : pinhole.params) line += " " + FormatFixed(p, 3);
  return line + " (fx fy cx cy)";
}

std::string SourceLine(const HousedCamera& source) {
  std::string line = source.camera.ModelName() + " " + std::to_string(source.camera.width) + " x " +
                     std::to_string(source.camera.height) + " px";
  if (source.housing)
    line += ", behind a " + source.housing->ModelName() + " (" + source.housing->InWords() + ")";
  return line + (source.housing ? "" : ", in air");
}

std::string PictureName(const CameraUndistortion& camera, const DepthError& depth) {
  return "camera_" + std::to_string(camera.pinhole.pinhole.camera_id) + "_error_at_" +
         FormatFixed(depth.depth, 2) + "m.png";
}

}  // namespace

std::vector<std::string> UndistortionWarnings(const std::vector<CameraUndistortion>& cameras,
                                              double max_error_px) {
  std::vector<std::string> warnings;
  for (const CameraUndistortion& camera : cameras) {
    if (camera.error.worst_px > max_error_px) {
      warnings.push_back(
          CameraName(camera) + ": the pinhole approximation errs by up to " +
          FormatFixed(camera.error.worst_px, 2) + " px (at " +
          FormatFixed(camera.error.worst_depth, 2) + " m) over " +
          FormatFixed(camera.range.near, 2) + "-" + FormatFixed(camera.range.far, 2) +
          " m, more than " + FormatShortest(max_error_px) +
          " px: what a pinhole tool measures away from the design depth is biased by that much "
          "(narrow --Undistort.depth_range, or keep the refractive model)");
    }
  }
  return warnings;
}

std::string UndistortionReportText(const std::vector<CameraUndistortion>& cameras,
                                   const std::vector<std::string>& warnings) {
  std::ostringstream out;
  for (const std::string& warning : warnings) out << "WARNING: " << warning << "\n";
  if (!warnings.empty()) out << "\n";
  for (const CameraUndistortion& camera : cameras) {
    const VirtualPinhole& pinhole = camera.pinhole;
    out << CameraName(camera) << ": " << SourceLine(pinhole.source) << "\n";
    out << "  virtual pinhole: " << PinholeLine(pinhole.pinhole) << "\n";
    if (camera.stereo_partner != 0) {
      out << "  rectified with camera " << camera.stereo_partner << ": baseline "
          << FormatFixed(camera.rectified_baseline, 4) << " m along the rectified x axis\n";
    }
    if (!pinhole.source.housing) {
      out << "  in air: the pinhole is exact at every depth (largest numerical error "
          << FormatShortest(camera.error.worst_px) << " px)\n\n";
      continue;
    }
    out << "  design depth: " << FormatFixed(pinhole.design_depth, 3) << " m ("
        << camera.depth_choice << ")\n";
    out << "  approximation error in output pixels (the pinhole's projection of a point at that "
           "depth\n"
        << "  against where the undistorted image shows it):\n";
    out << "    depth (m)      max     mean      p95\n";
    for (const DepthError& depth : camera.error.depths) {
      out << "    " << FormatFixed(depth.depth, 3)
          << (depth.depth == pinhole.design_depth ? "*" : " ") << "   "
          << FormatFixed(depth.max_px, 3) << "    " << FormatFixed(depth.mean_px, 3) << "    "
          << FormatFixed(depth.p95_px, 3) << "\n";
    }
    out << "  worst over " << FormatFixed(camera.range.near, 3) << "-"
        << FormatFixed(camera.range.far, 3) << " m: " << FormatFixed(camera.error.worst_px, 3)
        << " px at " << FormatFixed(camera.error.worst_depth, 3) << " m\n\n";
  }
  return out.str();
}

std::string UndistortionReportYaml(const std::vector<CameraUndistortion>& cameras,
                                   const std::vector<std::string>& warnings) {
  std::ostringstream out;
  out << "warnings:" << (warnings.empty() ? " []" : "") << "\n";
  for (const std::string& warning : warnings) out << "  - \"" << warning << "\"\n";
  out << "cameras:\n";
  for (const CameraUndistortion& camera : cameras) {
    const VirtualPinhole& pinhole = camera.pinhole;
    out << "  - camera_id: " << pinhole.pinhole.camera_id << "\n";
    out << "    source_model: " << pinhole.source.camera.ModelName() << "\n";
    out << "    housing: "
        << (pinhole.source.housing ? pinhole.source.housing->ModelName() : "NONE") << "\n";
    out << "    pinhole: {model: PINHOLE, width: " << pinhole.pinhole.width
        << ", height: " << pinhole.pinhole.height << ", params: [";
    for (size_t i = 0; i < pinhole.pinhole.params.size(); ++i) {
      out << (i ? ", " : "") << FormatShortest(pinhole.pinhole.params[i]);
    }
    out << "]}\n";
    const Eigen::Quaterniond rotation(pinhole.pinhole_from_cam);
    out << "    pinhole_from_cam_wxyz: [" << FormatShortest(rotation.w()) << ", "
        << FormatShortest(rotation.x()) << ", " << FormatShortest(rotation.y()) << ", "
        << FormatShortest(rotation.z()) << "]\n";
    if (camera.stereo_partner != 0) {
      out << "    stereo_partner: " << camera.stereo_partner << "\n";
      out << "    rectified_baseline_m: " << FormatShortest(camera.rectified_baseline) << "\n";
    }
    out << "    design_depth_m: " << FormatShortest(pinhole.design_depth) << "\n";
    out << "    depth_range_m: [" << FormatShortest(camera.range.near) << ", "
        << FormatShortest(camera.range.far) << "]\n";
    out << "    worst_error_px: " << FormatShortest(camera.error.worst_px) << "\n";
    out << "    errors:\n";
    for (const DepthError& depth : camera.error.depths) {
      out << "      - {depth_m: " << FormatShortest(depth.depth)
          << ", max_px: " << FormatShortest(depth.max_px)
          << ", mean_px: " << FormatShortest(depth.mean_px)
          << ", p95_px: " << FormatShortest(depth.p95_px) << "}\n";
    }
  }
  return out.str();
}

HtmlReport UndistortionHtml(const std::vector<CameraUndistortion>& cameras,
                            const std::vector<std::string>& warnings) {
  HtmlReport html;
  html.title = "portcal image_undistorter";
  html.warnings = warnings;
  html.sections.push_back({"Virtual pinholes", UndistortionReportText(cameras, {}), {}});
  for (const CameraUndistortion& camera : cameras) {
    if (!camera.pinhole.source.housing) continue;
    ReportSection section{
        CameraName(camera) + ": the approximation's error over the output image", "", {}};
    for (const DepthError& depth : camera.error.depths) {
      HeatMapStyle style;
      style.title = CameraName(camera) + " at " + FormatFixed(depth.depth, 2) + " m: max " +
                    FormatFixed(depth.max_px, 2) + " px";
      style.unit = "px";
      style.max_value =
          std::max(camera.error.worst_px, 1e-3);  // one colour scale for the camera's maps
      section.pictures.push_back(
          {PictureName(camera, depth),
           "Where the pinhole misplaces a point at " + FormatFixed(depth.depth, 2) +
               " m (design depth " + FormatFixed(camera.pinhole.design_depth, 2) + " m)",
           HeatMapPicture(depth.grid, static_cast<int>(camera.pinhole.pinhole.width),
                          static_cast<int>(camera.pinhole.pinhole.height), style)});
    }
    html.sections.push_back(std::move(section));
  }
  return html;
}

}  // namespace portcal
