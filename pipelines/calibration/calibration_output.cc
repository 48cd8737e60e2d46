#include "pipelines/calibration/calibration_output.h"

namespace portcal {

void WriteCalibrationOutput(const CalibrationReport& report, const std::filesystem::path& dir, Database* database,
                            camera_t camera_id) {
  if (database == nullptr) {
    WriteCalibrationReport(report, dir);
    return;
  }
  Transaction transaction = database->BeginTransaction();
  Camera calibrated = report.camera;
  calibrated.camera_id = camera_id;
  calibrated.has_prior_focal_length = true;
  database->UpdateCamera(calibrated);
  if (report.housing) database->WriteHousing(camera_id, *report.housing);
  WriteCalibrationReport(report, dir);
  transaction.Commit();
}

}  // namespace portcal
