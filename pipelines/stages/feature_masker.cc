#include "pipelines/stages/feature_masker.h"

#include <cstring>
#include <map>
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
    throw OptionError("--Mask.enlargement_factor", enlargement_factor, ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
  CheckArucoDictionaryOption("--Markers.dictionary", dictionary);
}

namespace {

// The features a mask starts from: those feature_extractor made, kept
// aside at the first masking (so that another mask can start from them
// again). True where they were kept before (the image was masked), false
// where they are the image's current features. Throws naming the image
// when the two tables disagree.
bool FeaturesBeforeMasking(const FeatureMaskerOptions& options, const DatabaseImage& image,
                           Database* database, FeatureKeypoints* keypoints,
                           FeatureDescriptors* descriptors) {
  if (database->ReadUnmaskedFeatures(image.image_id, keypoints, descriptors)) return true;
  *keypoints = database->ReadKeypoints(image.image_id);
  *descriptors = database->ReadDescriptors(image.image_id);
  if (static_cast<size_t>(descriptors->rows()) != keypoints->size()) {
    throw InputError(options.database_path + ": image '" + image.name + "' has " +
                     std::to_string(keypoints->size()) + " keypoints but " +
                     std::to_string(descriptors->rows()) + " descriptors");
  }
  database->WriteUnmaskedFeatures(image.image_id, *keypoints, *descriptors);
  return false;
}

bool SameKeypoints(const FeatureKeypoints& a, const FeatureKeypoints& b) {
  // memcmp's pointers must not be null even for 0 bytes, and an empty
  // vector's data() may be (UBSan, workflows/sanitize.sh: an image whose
  // features the mask removed).
  if (a.size() != b.size()) return false;
  return a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(FeatureKeypoint)) == 0;
}

// Keeps the features of one image inside its markers' enlarged quads (and
// deletes the image's matches if that changed its features).
void MaskImage(const FeatureMaskerOptions& options, const DatabaseImage& image,
               const std::vector<MarkerDetection>& markers, Database* database,
               FeatureMaskerSummary* summary) {
  const image_t image_id = image.image_id;
  database->WriteMarkerDetections(image_id, markers);
  summary->num_markers += static_cast<int64_t>(markers.size());
  summary->num_without_markers += markers.empty();
  FeatureKeypoints keypoints;
  FeatureDescriptors descriptors;
  if (options.keep_all_features &&
      !database->ReadUnmaskedFeatures(image_id, &keypoints, &descriptors)) {
    // Never masked: its features are as extracted (no copy kept aside).
    const int64_t count = static_cast<int64_t>(database->ReadKeypoints(image_id).size());
    summary->num_features_before += count;
    summary->num_features_kept += count;
    return;
  }
  const bool masked_before =
      FeaturesBeforeMasking(options, image, database, &keypoints, &descriptors);
  FeatureKeypoints kept_keypoints;
  std::vector<Eigen::Index> kept;
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const Eigen::Vector2d xy(keypoints[k].x, keypoints[k].y);
    // Kept features come back on an image without markers too.
    bool keep = options.keep_all_features;
    for (size_t m = 0; m < markers.size() && !keep; ++m) {
      keep = InsideEnlargedQuad(markers[m].corners, options.enlargement_factor, xy);
    }
    if (!keep) continue;
    kept.push_back(static_cast<Eigen::Index>(k));
    kept_keypoints.push_back(keypoints[k]);
  }
  summary->num_features_before += static_cast<int64_t>(keypoints.size());
  summary->num_features_kept += static_cast<int64_t>(kept.size());
  if (markers.empty() && !options.keep_all_features) {
    LOG(WARNING) << image.name << ": no " << options.dictionary
                 << " markers; all its features are removed";
  }
  // Unchanged (the same mask again): its matches stay valid.
  if (SameKeypoints(kept_keypoints, masked_before ? database->ReadKeypoints(image_id) : keypoints))
    return;
  FeatureDescriptors kept_descriptors(static_cast<Eigen::Index>(kept.size()), 128);
  for (size_t r = 0; r < kept.size(); ++r)
    kept_descriptors.row(static_cast<Eigen::Index>(r)) = descriptors.row(kept[r]);
  database->WriteKeypoints(image_id, kept_keypoints);
  database->WriteDescriptors(image_id, kept_descriptors);
  database->DeleteMatchesOfImage(image_id);
}

// "name=value" lines as a map.
std::map<std::string, std::string> ParseLines(const std::string& text) {
  std::map<std::string, std::string> values;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const size_t eq = line.find('=');
    if (eq != std::string::npos) values[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return values;
}

// The mask the features carry, as "dictionary, enlargement factor": that
// of the last feature_masker run since the last feature_extractor run that
// extracted every image; "" for none.
std::string MaskOfTheFeatures(Database* database) {
  std::string mask;
  for (const StageLogEntry& entry : database->ReadStageLog()) {
    const std::map<std::string, std::string> counts = ParseLines(entry.counts);
    if (entry.stage == "feature_extractor" && counts.count("extracted") && counts.count("images") &&
        counts.at("extracted") == counts.at("images")) {
      mask.clear();
    }
    if (entry.stage != "feature_masker") continue;
    std::map<std::string, std::string> options = ParseLines(entry.options);
    // Runs before the flag's rename logged Mask.dictionary.
    const std::string dictionary = options.count("Markers.dictionary")
                                       ? options["Markers.dictionary"]
                                       : options["Mask.dictionary"];
    mask = dictionary + ", enlargement factor " + options["Mask.enlargement_factor"];
    if (options["Mask.keep_all_features"] == "1")
      mask.clear();  // detections only: the features as extracted
  }
  return mask;
}

}  // namespace

FeatureMaskerSummary RunFeatureMasker(const FeatureMaskerOptions& options, ProgressSink& progress) {
  options.Check();
  std::ostringstream options_text;
  options_text << "image_path=" << options.image_path
               << "\nMarkers.dictionary=" << options.dictionary
               << "\nMask.enlargement_factor=" << options.enlargement_factor
               << "\nMask.keep_all_features=" << options.keep_all_features << "\n";
  StageRun run("feature_masker", options_text.str());
  Database database(options.database_path, Database::OpenMode::kReadWrite);
  Transaction transaction = database.BeginTransaction();
  const std::vector<DatabaseImage> images = database.ReadAllImages();
  if (images.empty())
    throw InputError(options.database_path + ": no images; run feature_extractor first");
  // Another mask starts from the features as extracted, kept aside at the
  // first masking; a database masked by a portcal that did not keep them
  // cannot bring back what that mask removed.
  std::ostringstream asked;
  asked << options.dictionary << ", enlargement factor " << options.enlargement_factor;
  if (options.keep_all_features) asked.str("every feature kept");
  const std::string mask = MaskOfTheFeatures(&database);
  if (!mask.empty() && mask != asked.str() && database.NumImagesWithUnmaskedFeatures() == 0) {
    throw InputError(options.database_path + ": its features were masked before (" + mask +
                     ") without keeping them as extracted; a mask cannot bring back what an "
                     "earlier one removed, "
                     "so " +
                     asked.str() +
                     " was not applied: extract the features again (feature_extractor "
                     "--overwrite 1, or a new database or output folder), then mask");
  }

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
    throw InputError(options.database_path + ": no " + options.dictionary +
                     " marker in any of the " + std::to_string(summary.num_images) +
                     " images under " + options.image_path +
                     "; nothing was changed (markers of another dictionary? --Markers.dictionary)");
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
            << " images; kept " << summary.num_features_kept << " of "
            << summary.num_features_before << " features";
  return summary;
}

}  // namespace portcal
