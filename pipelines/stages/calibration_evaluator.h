// `portcal calibration_evaluator`: a calibration (lens, or lens and
// housing) judged on the target views of a database it need not have been
// fitted to: each view's pose alone with the calibration fixed, per-view
// and overall RMS, the residuals' pattern over the image; with
// --Evaluation.folds K, K-fold cross-validation of the same kind of
// calibration on these views. Writes evaluation.yaml and evaluation.txt.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/held_out_evaluation.h"

namespace portcal {

struct CalibrationEvaluatorOptions {
  std::string database_path;
  std::string input_calibration;  // calibration.yaml (portcal or calibmar), with its housing if any
  std::string output_path;
  int camera_id = -1;  // -1: the only camera with target observations
  int folds = 0;       // 0: none, else >= 2
  int num_threads = 2;
  void Check() const;  // throws OptionError naming the option
};

struct CalibrationEvaluatorSummary {
  HeldOutEvaluation evaluation;
  std::vector<FoldEvaluation> folds;
  double cross_validation_rms_px = 0;  // over every held-out point of every fold
};

// Throws InputError (the database, the calibration, a camera of another
// size) and NumericalError (no view can be evaluated).
CalibrationEvaluatorSummary RunCalibrationEvaluator(const CalibrationEvaluatorOptions& options,
                                                    ProgressSink& progress);

}  // namespace portcal
