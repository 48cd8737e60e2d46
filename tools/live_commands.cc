#include "colmap_ext/util/progress.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/stages/live_calibrator.h"
#include "pipelines/stages/pose_suggester.h"
#include "tools/command_line.h"
#include "tools/commands.h"
#include "tools/option_groups.h"

namespace portcal {
namespace {

// --Live.* of next-pose guidance: the poses a person can hold.
void RegisterGuidance(CommandLine* cli, NextPoseOptions* guidance) {
  cli->AddRange(
      "Live.distance_range", &guidance->distance_min_m, &guidance->distance_max_m,
      "suggested target distances, metres, camera to target centre (what the person can reach)");
  cli->Add("Live.max_tilt_deg", &guidance->tilt_max_deg,
           "suggested tilts up to this (target normal vs line of sight)");
  cli->Add("Live.max_roll_deg", &guidance->roll_max_deg,
           "suggested rolls about the line of sight up to this");
  cli->Add("Live.margin_px", &guidance->border_margin_px,
           "suggested poses keep the whole target this far inside");
  cli->Add("Live.num_candidates", &guidance->num_candidates, "poses scored per suggestion");
  cli->Add("Live.working_distance", &guidance->uncertainty.working_distance_m,
           "depth at which projection uncertainty is measured, metres (0: the middle of the "
           "distance range)");
}

// --Live.*: the source's pacing, hands-free capture, next-pose guidance.
void RegisterLive(CommandLine* cli, LiveSessionOptions* live) {
  cli->Add("Live.fps", &live->source.folder_fps,
           "frame rate of a folder of images played as a source");
  cli->Add("Live.realtime", &live->source.realtime,
           "files and folders play at their frame rate, late frames dropped (1), or every frame as "
           "fast as it "
           "is processed (0)");
  cli->Add("Live.stall_seconds", &live->source.stall_seconds,
           "a live source without a frame this long is stalled (a warning; three in a row end the "
           "session)");
  cli->Add(
      "Live.target_uncertainty_px", &live->goal.target_uncertainty_px,
      "the goal: mean expected projection uncertainty at the working distance, px (docs/live.md)");
  cli->Add("Live.auto_finish", &live->goal.auto_finish,
           "finish by itself once the goal is met (0 | 1)");
  HandsFreeOptions& hands_free = live->hands_free;
  cli->Add("Live.hands_free", &hands_free.enabled,
           "keep frames when the target is held still (0 | 1)");
  cli->Add("Live.still_px", &hands_free.still_px,
           "held still: every corner within this many pixels ...");
  cli->Add("Live.still_seconds", &hands_free.still_seconds, "... for this long");
  cli->Add("Live.novelty", &hands_free.novelty_fraction,
           "a new view's corners must lie this far (fraction of the image diagonal, mean) from "
           "every kept view's");
  cli->Add(
      "Live.min_gain", &hands_free.min_gain,
      "once estimated, a new view must lower the expected projection uncertainty by this fraction");
  RegisterGuidance(cli, &live->estimator.guidance);
  cli->Add("Live.max_views", &live->max_views,
           "finish after this many kept views (0: when the source ends)");
  cli->Add("Live.status_interval", &live->status_interval_s,
           "seconds between status lines on stderr (0: none)");
}

}  // namespace

int LiveCalibratorCommand(int argc, char** argv) {
  LiveCalibratorOptions options;
  options.live.estimator.guidance.uncertainty.working_distance_m = 0;
  std::string fixed;
  CommandLine cli(
      "live_calibrator",
      "Calibrates from a camera, a video file or a network stream: frames where the target is held "
      "still are kept (hands-free), written to --image_path and imported into the database as "
      "target_extractor would; after each kept view the estimate, its uncertainty and the next "
      "suggested pose are printed; at the end camera_calibrator (or, with --input_calibration and "
      "--Housing.*, housing_calibrator) writes the reports. Ctrl-C stops with every view kept.");
  cli.AddRequired(
      "source", &options.live.source.source,
      "/dev/videoN or an index (V4L2), a video file, a folder of images, an rtsp:// URL, or a "
      "GStreamer pipeline ending in appsink");
  cli.Add("source2", &options.live.source2,
          "a stereo rig's camera 2 (a source of the same kind): frames paired by time, kept in "
          "cam1/ and cam2/, "
          "each camera calibrated (OUT/cam1, OUT/cam2), then stereo_calibrator (OUT)");
  cli.Add("Live.pair_tolerance", &options.live.pair_tolerance_s,
          "stereo: frames of the two sources pair when their times differ by at most this, seconds "
          "(0: half a frame interval)");
  cli.AddRequired("database_path", &options.database_path,
                  "database (created if missing; a rerun adds views)");
  cli.AddRequired("image_path", &options.image_path,
                  "folder for the kept frames (created if missing)");
  cli.AddRequired("output_path", &options.output_path, "folder for the final reports");
  Register(&cli, &options.reader);
  TargetDetectorOptions& target = options.live.detector;
  Register(&cli, &target);
  cli.Add("input_calibration", &options.input_calibration,
          "in-air calibration.yaml: calibrate the housing");
  cli.Add("input_calibration2", &options.input_calibration2,
          "stereo behind housings: camera 2's in-air calibration.yaml (its port starts from "
          "--Housing.params too)");
  cli.AddHousing(&options.housing, "the port to calibrate (with --input_calibration)");
  cli.Add("Calibration.fixed_params", &fixed,
          "camera calibration: parameters to hold, comma separated");
  cli.Add("Calibration.estimate_board_warp", &options.live.estimator.estimate_board_warp,
          "fit the board's sag, live and at the end alike (0: a rigid board held flat)");
  RegisterLive(&cli, &options.live);
  cli.Add("Live.address", &options.page.address,
          "where the live page is served, HOST:PORT (0.0.0.0:PORT: seen from other machines; port "
          "0: a free one)");
  cli.Add("Live.token", &options.page.token,
          "a password every request must carry (16-128 of A-Z a-z 0-9 _ -): the printed address "
          "holds it, the "
          "page keeps it in a cookie; set it with 0.0.0.0 on a shared network");
  cli.Add("Live.headless", &options.page.headless,
          "no page: state and suggestions on stderr only (0 | 1)");
  cli.Add("Live.max_width", &options.page.max_width,
          "frames on the page scaled down to this width, pixels");
  cli.Add("calibrate_at_end", &options.calibrate_at_end,
          "write the final reports when the session ends (0 | 1)");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    options.fixed_params = SplitTokens(fixed, ", ");
    StderrProgress progress;
    RunLiveCalibrator(options, progress);
  });
}

int PoseSuggesterCommand(int argc, char** argv) {
  PoseSuggesterOptions options;
  options.guidance.uncertainty.working_distance_m = 0;
  std::string fixed;
  CommandLine cli(
      "pose_suggester",
      "The next target poses to hold, from the views a database holds so far (none: the opening "
      "sequence): each the pose that most lowers the expected projection uncertainty over the "
      "image. "
      "Writes suggested_poses.txt (cam_from_target per pose) and suggested_pose_NN.png (where the "
      "target must appear).");
  cli.AddRequired("database_path", &options.database_path, "database with the views so far");
  cli.AddRequired("output_path", &options.output_path, "folder for the suggestions");
  cli.Add("num_poses", &options.num_poses, "how many poses");
  cli.Add("camera_id", &options.camera_id, "camera (-1: the only one)");
  Register(&cli, &options.target);
  cli.Add("input_calibration", &options.input_calibration,
          "in-air calibration.yaml: guide a housing calibration");
  cli.AddHousing(&options.housing, "the port being calibrated (with --input_calibration)");
  cli.Add("Calibration.fixed_params", &fixed,
          "camera calibration: parameters held, comma separated");
  RegisterGuidance(&cli, &options.guidance);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    options.fixed_params = SplitTokens(fixed, ", ");
    StderrProgress progress;
    RunPoseSuggester(options, progress);
  });
}

}  // namespace portcal
