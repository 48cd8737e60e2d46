#include "pipelines/stages/feature_masker.h"

#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "database/database.h"
#include "database/stage_run.h"
#include "pipelines/markers/aruco.h"
#include "pipelines/markers/aruco_markers.h"

namespace fs = std::filesystem;

namespace portcal {

void FeatureMaskerOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "a directory of images");
  if (!(enlargement_factor >= 1.0)) {
    throw OptionError("--Mask.enlargement_factor", std::to_string(enlargement_factor), ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
  ArucoDictionaryByName(dictionary);  // throws naming the known ones
}

namespace {

// Keeps the features of one image inside its markers' enlarged quads (and
// deletes the image's matches if that changed its features).
void MaskImage(const FeatureMaskerOptions& options, const DatabaseImage& image,
               const std::vector<MarkerDetection>& markers, Database* database, FeatureMaskerSummary* summary) {
  const image_t image_id = image.image_id;
  database->WriteMarkerDetections(image_id, markers);
  summary->num_markers += static_cast<int64_t>(markers.size());
  const FeatureKeypoints keypoints = database->ReadKeypoints(image_id);
  const FeatureDescriptors descriptors = database->ReadDescriptors(image_id);
  if (static_cast<size_t>(descriptors.rows()) != keypoints.size()) {
    throw InputError(options.database_path + ": image '" + image.name + "' has " +
                     std::to_string(keypoints.size()) + " keypoints but " +
                     std::to_string(descriptors.rows()) + " descriptors");
  }
  std::vector<size_t> kept;
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const Eigen::Vector2d xy(keypoints[k].x, keypoints[k].y);
    for (const MarkerDetection& marker : markers) {
      if (InsideEnlargedQuad(marker.corners, options.enlargement_factor, xy)) {
        kept.push_back(k);
        break;
      }
    }
  }
  summary->num_features_before += static_cast<int64_t>(keypoints.size());
  summary->num_features_kept += static_cast<int64_t>(kept.size());
  if (markers.empty()) {
    ++summary->num_without_markers;
    LOG(WARNING) << image.name << ": no " << options.dictionary << " markers; all its features are removed";
  }
  if (kept.size() == keypoints.size()) return;  // unchanged: its matches stay valid
  FeatureKeypoints kept_keypoints;
  FeatureDescriptors kept_descriptors(static_cast<Eigen::Index>(kept.size()), 128);
  for (size_t r = 0; r < kept.size(); ++r) {
    kept_keypoints.push_back(keypoints[kept[r]]);
    kept_descriptors.row(static_cast<Eigen::Index>(r)) = descriptors.row(static_cast<Eigen::Index>(kept[r]));
  }
  database->WriteKeypoints(image_id, kept_keypoints);
  database->WriteDescriptors(image_id, kept_descriptors);
  database->DeleteMatchesOfImage(image_id);
}

}  // namespace

FeatureMaskerSummary RunFeatureMasker(const FeatureMaskerOptions& options, ProgressSink& progress) {
  options.Check();
  std::ostringstream options_text;
  options_text << "image_path=" << options.image_path << "\nMask.dictionary=" << options.dictionary
               << "\nMask.enlargement_factor=" << options.enlargement_factor << "\n";
  StageRun run("feature_masker", options_text.str());
  Database database(options.database_path, Database::OpenMode::kReadWrite);
  Transaction transaction = database.BeginTransaction();
  const std::vector<DatabaseImage> images = database.ReadAllImages();
  if (images.empty()) throw InputError(options.database_path + ": no images; run feature_extractor first");

  std::vector<std::vector<MarkerDetection>> detections(images.size());
  FeatureMaskerSummary summary;
  summary.num_images = static_cast<int>(images.size());
  progress.Begin("feature_masker: images", images.size());
  OrderedParallelFor(
      images.size(), options.num_threads, 2 * static_cast<size_t>(options.num_threads) + 2,
      [&](size_t i) {
        const fs::path path = fs::path(options.image_path) / images[i].name;
        const cv::Mat gray = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
        if (gray.empty()) {
          throw InputError(path.string() + ": cannot read image '" + images[i].name +
                           "' named in the database (wrong --image_path?)");
        }
        detections[i] = DetectArucoMarkers(gray, options.dictionary);
      },
      [&](size_t i) {
        progress.Advance(1);
        MaskImage(options, images[i], detections[i], &database, &summary);
      });
  progress.End();
  if (summary.num_without_markers == summary.num_images) {
    // Every feature would go: markers of another dictionary, most likely.
    throw InputError(options.database_path + ": no " + options.dictionary + " marker in any of the " +
                     std::to_string(summary.num_images) + " images under " + options.image_path +
                     "; nothing was changed (markers of another dictionary? --Mask.dictionary, "
                     "--Markers.dictionary in auto_calibrator)");
  }
  run.Finish(&database, {{"images", summary.num_images},
                         {"without_markers", summary.num_without_markers},
                         {"markers", summary.num_markers},
                         {"features_before", summary.num_features_before},
                         {"features_kept", summary.num_features_kept}});
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  LOG(INFO) << "feature_masker: " << summary.num_markers << " markers in "
            << summary.num_images - summary.num_without_markers << " of " << summary.num_images
            << " images; kept " << summary.num_features_kept << " of " << summary.num_features_before
            << " features";
  return summary;
}

}  // namespace portcal
