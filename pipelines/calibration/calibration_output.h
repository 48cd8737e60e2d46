// Where a target calibration goes: its reports, and on request the
// database, so that the next stage (portcal's or COLMAP's) starts from it.
#pragma once

#include <filesystem>
#include <functional>

#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {

// Writes calibration.yaml / .txt into `dir` and, with a database, the
// report's camera into camera `camera_id` (its parameters, with a prior
// focal length) and its housing into portcal_housings, in one transaction
// committed once the reports are written: a failure leaves the database as
// it was.
// `write_beside` (optional) writes further files into `dir` after the
// reports and before the commit.
void WriteCalibrationOutput(const CalibrationReport& report, const std::filesystem::path& dir,
                            Database* database, camera_t camera_id,
                            const std::function<void()>& write_beside = {});

}  // namespace portcal
