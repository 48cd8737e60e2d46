#include <iostream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/stages/image_undistorter.h"
#include "pipelines/stages/model_converter.h"
#include "pipelines/stages/project_points.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

int ModelConverterCommand(int argc, char** argv) {
  ModelConverterOptions options;
  CommandLine cli("model_converter",
                  "Converts a COLMAP sparse model (cameras, images, points3D "
                  "and portcal's housings.txt) between BIN and TXT; a cameras.txt of the "
                  "refractive COLMAP fork (housing after the camera parameters) is imported "
                  "into housings.txt. Also converts one camera: from a model, a portcal "
                  "calibration.yaml or an mrcal .cameramodel, to an mrcal .cameramodel "
                  "(LENSMODEL_PINHOLE / OPENCV4 / OPENCV8), OpenCV's YAML (camera_matrix, "
                  "distortion_coefficients) or ROS camera_info YAML; or a .cameramodel to a "
                  "COLMAP model (BIN / TXT, cameras only).");
  cli.AddRequired("input_path", &options.input_path,
                  "model directory, .cameramodel or calibration.yaml");
  cli.AddRequired("output_path", &options.output_path,
                  "model directory (BIN, TXT) or file (CAMERAMODEL, OPENCV_YAML, ROS_YAML)");
  cli.Add("output_type", &options.output_type, "BIN | TXT | CAMERAMODEL | OPENCV_YAML | ROS_YAML");
  cli.Add("camera_id", &options.camera_id, "camera to export from a model (-1: the only one)");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunModelConverter(options, progress);
  });
}

int ImageUndistorterCommand(int argc, char** argv) {
  ImageUndistorterOptions options;
  CommandLine cli(
      "image_undistorter",
      "Writes pinhole images and a pinhole model for the tools that take only pinholes, as "
      "`colmap image_undistorter` does: from a sparse model (with housings.txt, or a stock one) a "
      "COLMAP dense workspace (images/, sparse/ with PINHOLE cameras and the same poses, stereo/, "
      "run-colmap-*.sh); from one calibration file the undistorted images of --image_path and the "
      "camera. Behind a port no pinhole is exact: the virtual pinhole is exact at a design depth "
      "(--Undistort.distance, or the one with the smallest worst error over "
      "--Undistort.depth_range) and undistortion.txt, undistortion.yaml and report/report.html "
      "give and draw its error over the range. Depths are z in the camera frame, metres.");
  cli.AddRequired(
      "input_path", &options.input_path,
      "sparse model folder, or a calibration file "
      "(portcal's or calibmar's calibration.yaml, OpenCV or ROS YAML, mrcal .cameramodel)");
  cli.AddRequired("image_path", &options.image_path, "folder of the input images");
  cli.AddRequired("output_path", &options.output_path, "workspace folder to write (created)");
  cli.Add("Undistort.blank_pixels", &options.field_of_view.blank_pixels,
          "0: only pixels the camera saw; 1: every pixel of the camera kept (blank corners)");
  cli.Add("Undistort.min_scale", &options.field_of_view.min_scale,
          "smallest output size over the input's");
  cli.Add("Undistort.max_scale", &options.field_of_view.max_scale,
          "largest output size over the input's");
  cli.Add("Undistort.max_image_size", &options.field_of_view.max_image_size,
          "largest output side, px (-1: any)");
  cli.Add("Undistort.distance", &options.distance, "design depth behind a port, m (0: not given)");
  cli.AddRange(
      "Undistort.depth_range", &options.depth_range.near, &options.depth_range.far,
      "NEAR,FAR in m: the error is reported over it, and without --Undistort.distance the design "
      "depth minimises its worst (0,0: not given; the model's point depths)");
  cli.Add("Undistort.num_error_depths", &options.num_error_depths,
          "depths the error is reported and drawn at");
  cli.Add("Undistort.max_error_px", &options.max_error_px, "a worst error above this is a warning");
  cli.Add("Undistort.write_maps", &options.write_maps,
          "write maps/camera_<id>.yaml.gz: map_x, map_y (float32) for cv::remap (0 | 1)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunImageUndistorter(options, progress);
  });
}

int ProjectPointsCommand(int argc, char** argv) {
  ProjectPointsOptions options;
  CommandLine cli("project_points",
                  "Projects 3-D points (camera frame, metres; one 'X Y Z' per "
                  "line) through a camera and optional housing and prints one "
                  "'x y' pixel per line (COLMAP convention: top-left pixel "
                  "centre at 0.5, 0.5). With --unproject, reads 'x y' pixels "
                  "and prints rays 'ox oy oz dx dy dz' (in water behind a "
                  "housing). Points without an answer print 'invalid ...'.");
  cli.AddRequired("points_path", &options.points_path, "input text file");
  cli.Add("unproject", &options.unproject, "pixels -> rays (0 | 1)");
  cli.Add("input_path", &options.input_path,
          "sparse model to take the camera (and housings.txt) from");
  cli.Add("camera_id", &options.camera_id, "camera id in --input_path (-1: its only camera)");
  cli.Add("input_calibration", &options.input_calibration,
          "calibration file to take the camera (and housing) from: portcal's or calibmar's "
          "calibration.yaml, "
          "OpenCV or ROS camera YAML, mrcal .cameramodel");
  cli.Add("Camera.model", &options.camera_model, "COLMAP camera model name");
  cli.Add("Camera.params", &options.camera_params, "parameters in COLMAP's order");
  cli.Add("Camera.width", &options.width, "image width, pixels");
  cli.Add("Camera.height", &options.height, "image height, pixels");
  cli.AddHousing(
      &options.housing,
      "the housing in front of the camera (none: in air; replaces --input_calibration's)");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    for (const std::string& line : RunProjectPoints(options, progress).lines)
      std::cout << line << "\n";
    std::cout.flush();
    if (!std::cout)
      throw InputError("standard output: writing the answers failed (disk full or closed?)");
  });
}

}  // namespace portcal
