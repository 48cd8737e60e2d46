#include "pipelines/calibration/calibration_output.h"

namespace portcal {

void WriteCalibrationOutput(const CalibrationReport& report, const std::filesystem::path& dir, Database* database,
                            camera_t camera_id, const std::function<void()>& write_beside) {
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
