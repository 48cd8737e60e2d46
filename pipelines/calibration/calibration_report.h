// calibration.yaml (calibmar's keys, so calibmar imports it, plus portcal's
// own: standard deviations, RMS, per-view table, target) and calibration.txt
// for people. The report is built from a result with its notes and warnings
// in calibration_report.cc, written in calibration_report_writer.cc, read
// in calibration_report_reader.cc.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/calibration/calibration_verdict.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/stereo_calibration.h"

namespace portcal {

// mrcal's projection uncertainty (pipelines/guidance/projection_uncertainty.h)
// on a grid over the image, as data a script can compare: the
// worst-direction standard deviation (px) at the grid's cell centres, at
// the working distance (depth z in the camera frame) and at infinity.
struct ProjectionUncertaintyGrid {
  std::string of;  // "intrinsics" or "housing": what is uncertain
  double working_distance_m = 0;
  double pixel_sigma_px = 0;       // the corners' noise propagated (residual sigma)
  std::vector<double> x_px, y_px;  // cell centres, COLMAP pixels: per column, per row
  // rows x cols (y_px.size() x x_px.size()); -1 where no ray.
  Eigen::MatrixXd at_working_distance_px, at_infinity_px;
  bool determined = true;               // false: the views do not fix the unknowns (maps all -1)
  double Mean(bool at_infinity) const;  // over the cells with a ray
  double Max(bool at_infinity) const;
};

struct CalibrationReport {
  Camera camera;
  std::vector<double> parameters_std_dev;
  std::optional<Housing> housing;
  std::vector<double> housing_std_dev;
  // Full covariances (the residual variance applied) of the camera's and
  // the housing's parameters, in their orders; zero rows and columns for
  // what is held; empty where not estimated or undetermined. A later stage
  // propagates them (housing_calibrator: the lens's into the port's).
  Eigen::MatrixXd parameters_covariance, housing_covariance;
  // Auto-calibration: the two estimates behind the std devs above, which
  // are the larger of them: by the noise model (the covariance, every
  // residual independent) and by the clusters' spread (the covariance
  // clustered by image and by track). Empty elsewhere.
  std::vector<double> parameters_std_dev_by_noise, parameters_std_dev_by_clusters;
  std::vector<double> housing_std_dev_by_noise, housing_std_dev_by_clusters;
  double overall_rms_px = 0;
  double residual_sigma_px = 0;
  int num_points = 0;
  std::vector<CalibratedView> views;
  // The frame the views' poses map from: "target" (a calibration target),
  // "world" (a self-calibration's reconstruction); the per-view key is
  // cam_from_<pose_frame>.
  std::string pose_frame = "target";
  std::string target_description;  // e.g. "chessboard 10x7, square 0.02 m"
  std::optional<Eigen::Vector2d> board_warp, board_warp_std_dev;
  // Decisions a reader needs to weigh the numbers (e.g. a parameter held
  // because the data could not tell it from its default).
  std::vector<std::string> notes;
  // Reasons not to trust the result (e.g. a focal length whose standard
  // deviation is a large fraction of it): written first in both files.
  std::vector<std::string> warnings;
  // Target calibrations: how far a projection can be trusted over the image.
  std::optional<ProjectionUncertaintyGrid> projection_uncertainty;
  // Whether to keep it (JudgeCalibration), written first when set.
  std::optional<CalibrationVerdict> verdict;
};

// The report of a camera calibration (with the board warp when it was
// estimated) and of a housing calibration, of the target `target`.
CalibrationReport ReportOf(const CameraCalibrationResult& result, bool with_board_warp,
                           const std::string& target);
CalibrationReport ReportOf(const HousingCalibrationResult& result, const std::string& target);

// What a fitted board warp means for the calibration: the sag, whether it
// is significant against its standard deviation, and how far the focal
// length and principal point would move held flat (`flat`: the same views
// calibrated with the board held flat), in pixels and standard deviations.
std::string BoardWarpNote(const CameraCalibrationResult& warped,
                          const CameraCalibrationResult& flat);

// calibration.txt's text.
std::string CalibrationReportText(const CalibrationReport& report);

// Writes calibration.yaml and calibration.txt into `dir` (created),
// atomically.
void WriteCalibrationReport(const CalibrationReport& report, const std::filesystem::path& dir);

// Stereo: calibmar's cam_to_world_rotation_rowmajor / cam_to_world_translation
// (camera 2 in the camera-1 frame), cam2_from_cam1 (rotation_wxyz,
// translation) with standard deviations, and a block per camera; the
// verdict first when given. Returns calibration.txt's text.
std::string WriteStereoCalibrationReport(const StereoCalibrationResult& result,
                                         const HousedCamera& camera1, const HousedCamera& camera2,
                                         const std::string& target_description,
                                         const std::filesystem::path& dir,
                                         const CalibrationVerdict* verdict = nullptr);

// Reads the camera (and housing) of a calibration.yaml written by portcal or
// calibmar, and portcal's standard deviations, board warp, target, notes and per-view table
// (names, RMS, outlier/dropped flags; poses are not read back) when present.
// Also reads the camera alone from OpenCV's FileStorage YAML, ROS camera_info
// YAML and mrcal's .cameramodel (the format told by the extension and the
// keys). Throws InputError naming the file and the missing key, and the
// formats it reads.
CalibrationReport ReadCalibrationReport(const std::filesystem::path& path);

}  // namespace portcal
