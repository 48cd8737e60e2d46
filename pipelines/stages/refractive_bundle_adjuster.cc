#include "pipelines/stages/refractive_bundle_adjuster.h"

#include <cmath>
#include <optional>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "database/database.h"
#include "pipelines/report/calibration_html.h"

namespace portcal {

void RefractiveBundleAdjusterOptions::Check() const {
  if (input_path.empty()) throw OptionError("--input_path", "''", "a sparse model directory");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a directory for the results");
  CheckOutputFolder("--output_path", output_path);
  if (marker_scale.side_length_m > 0 && database_path.empty()) {
    throw OptionError("--database_path", "''",
                      "the database with the marker detections (--Markers.side_length)");
  }
  if (ba.position_prior_sigma_m > 0 && database_path.empty()) {
    throw OptionError("--database_path", "''",
                      "the database with the position priors (--PosePrior.position_sigma)");
  }
  SelfCalibrationOptions::Check();
}

namespace {

// An image's marker detections, position prior and, when the model's
// points are the database's keypoints, their scales (for weighting).
void AddDatabaseExtras(Database* database, SfmImage* image) {
  const auto row = database->ReadImageWithName(image->name);
  if (!row) return;
  SfmImage read;
  read.markers = database->ReadMarkerDetections(row->image_id);
  read.position_prior = row->PriorPosition();
  for (const FeatureKeypoint& k : database->ReadKeypoints(row->image_id)) {
    read.keypoints.emplace_back(k.x, k.y);
    read.scales.push_back(k.ComputeScale());
  }
  AddExtrasOf(read, image);
}

}  // namespace

RefractiveBundleAdjusterSummary RunRefractiveBundleAdjuster(
    const RefractiveBundleAdjusterOptions& options, ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  ModelSource source;
  source.model_name = options.input_path;
  source.database_name = options.database_path;
  source.load_model = [&] { return ReadSparseModel(options.input_path); };
  std::optional<Database> database;  // opened once the model is read
  if (!options.database_path.empty()) {
    source.add_extras = [&](SfmImage* image) {
      if (!database) database.emplace(options.database_path, Database::OpenMode::kReadOnly);
      AddDatabaseExtras(&*database, image);
    };
  }
  const RefinedModel refined = RefineModel(options, source);
  const CalibrationReport& report = refined.summary.report;
  WriteSparseModel(refined.model, options.output_path, ModelFormat::kBinary);
  WriteCalibrationReport(report, options.output_path);
  WriteHtml(SelfCalibrationHtml(report, refined.model, "Refractive bundle adjustment"),
            options.output_path);
  LOG(INFO) << "refractive_bundle_adjuster: RMS " << report.overall_rms_px << " px over "
            << report.num_points << " observations; " << refined.summary.num_filtered
            << " observations dropped; written to " << options.output_path;
  if (report.housing) {
    std::string params;
    for (double v : report.housing->params) params += std::to_string(v) + " ";
    LOG(INFO) << "housing: " << report.housing->ModelName() << " " << params;
  }
  new_output.Keep();
  return refined.summary;
}

}  // namespace portcal
