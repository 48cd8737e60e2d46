#include "pipelines/calibration/calibration_output.h"

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/progress.h"

namespace portcal {

void WriteCalibrationOutput(const CalibrationReport& report, const std::filesystem::path& dir,
                            Database* database, camera_t camera_id,
                            const std::function<void()>& write_beside) {
  // The last moment to honour a stop: a SIGINT during the report's pictures
  // would otherwise end in a complete output and exit 0.
  if (CancelFlag::Requested()) {
    throw Cancelled("nothing was written (" + dir.string() +
                    (database ? " and the database are" : " is") + " as it was)");
  }
  if (database == nullptr) {
    WriteCalibrationReport(report, dir);
    if (write_beside) write_beside();
    return;
  }
  Transaction transaction = database->BeginTransaction();
  Camera calibrated = report.camera;
  calibrated.camera_id = camera_id;
  calibrated.has_prior_focal_length = true;
  database->UpdateCamera(calibrated);
  if (report.housing) database->WriteHousing(camera_id, *report.housing);
  WriteCalibrationReport(report, dir);
  if (write_beside) write_beside();
  transaction.Commit();
}

}  // namespace portcal
