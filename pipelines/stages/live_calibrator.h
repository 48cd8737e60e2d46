// `portcal live_calibrator`: a calibration from a camera, a video file or a
// network stream. Frames where the target is held still (or asked for) are
// written to --image_path and imported into the database as
// target_extractor would (same tables, same precise corners), one
// transaction per frame, so an interrupted session keeps every view; at the
// end the views are calibrated by camera_calibrator or housing_calibrator
// (the same reports as those commands give on this database). With two
// sources, a stereo rig: pairs of frames in cam1/ and cam2/, each camera
// calibrated, then stereo_calibrator.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/stereo_calibration.h"
#include "pipelines/images/image_reader.h"
#include "pipelines/live/live_server.h"
#include "pipelines/live/live_session.h"

namespace portcal {

struct LiveCalibratorOptions {
  std::string database_path;  // created if missing; a continued session adds to it
  std::string image_path;     // kept frames (live_0001.png, ...), created if missing
  std::string output_path;    // the final reports
  ImageReaderOptions reader;  // the camera model (one camera for every frame)
  // Housing calibration: the in-air calibration.yaml and the port (its
  // constants and a start); camera calibration without them.
  std::string input_calibration;
  std::optional<Housing> housing;
  // A rig (--source2 in `live`): camera 2's in-air calibration for a
  // housing calibration (its housing starts from `housing` too).
  std::string input_calibration2;
  std::vector<std::string> fixed_params;  // camera calibration
  LiveSessionOptions live;                // source, target, hands-free, guidance
  LivePageOptions page;                   // the live view in a browser (or headless)
  bool calibrate_at_end = true;
  void Check() const;  // throws OptionError naming the option
};

struct LiveCalibratorSummary {
  LiveSummary session;
  bool calibrated = false;  // the final reports were written
  // The final calibration (the one the reports give).
  std::optional<CameraCalibrationResult> camera;
  std::optional<HousingCalibrationResult> housing;
  // A rig: camera 2's (in OUT/cam2; camera 1's in OUT/cam1) and the rig's.
  std::optional<CameraCalibrationResult> camera2;
  std::optional<HousingCalibrationResult> housing2;
  std::optional<StereoCalibrationResult> stereo;
};

// `on_start` is called with the session (and the page's address, "" when
// headless) before the first frame. Throws InputError (options, the source, the
// input calibration), NumericalError (too few views for the final
// calibration: they stay in the database), Cancelled after Ctrl-C (every
// view kept so far stays).
LiveCalibratorSummary RunLiveCalibrator(
    const LiveCalibratorOptions& options, ProgressSink& progress,
    const std::function<void(LiveSession&, const std::string&)>& on_start = {});

}  // namespace portcal
