// `portcal target_extractor`: imports images into the database (as COLMAP's
// ImageReader) and stores the calibration target's corners seen in each,
// with per-image status, in one transaction.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/images/image_reader.h"

namespace portcal {

struct TargetExtractorOptions {
  std::string database_path;  // created if missing
  std::string image_path;     // directory of images
  ImageReaderOptions reader;
  std::string target_type = "chessboard";  // chessboard | aruco_grid | charuco
  ChessboardDetectionOptions chessboard;
  double square_size_m = 0.02;  // chessboard and charuco squares, > 0
  MarkerBoardOptions markers;   // aruco_grid and charuco
  int num_threads = 2;          // >= 1
  void Check() const;           // throws OptionError naming the option
};

struct TargetExtractorSummary {
  int num_images = 0;
  int num_found = 0;
  int64_t num_points = 0;
};

// The detector the options describe (precise fits).
TargetDetectorOptions DetectorOptions(const TargetExtractorOptions& options);

// Throws InputError (bad options, no images), DatabaseError, Cancelled; the
// database is then left as it was.
TargetExtractorSummary RunTargetExtractor(const TargetExtractorOptions& options,
                                          ProgressSink& progress);

}  // namespace portcal
