#include "pipelines/stages/feature_masker.h"

#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "database/database.h"
#include "pipelines/markers/aruco.h"
#include "database/stage_run.h"
#include "pipelines/markers/marker_edge_refinement.h"

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

std::vector<MarkerDetection> DetectArucoMarkers(const cv::Mat& gray, const std::string& dictionary) {
  const cv::Ptr<cv::aruco::Dictionary> dict = ArucoDictionaryByName(dictionary);
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dict, corners, ids, parameters);
  std::vector<MarkerDetection> markers;
  MarkerEdgeRefinementOptions refinement;
  refinement.bits_per_side = dict->markerSize;
  for (size_t m = 0; m < ids.size(); ++m) {
    MarkerDetection detection;
    detection.dictionary = dictionary;
    detection.marker_id = ids[m];
    std::array<cv::Point2d, 4> quad;
    for (int c = 0; c < 4; ++c) quad[c] = cv::Point2d(corners[m][c].x, corners[m][c].y);
    // Edge-line corners where the edges allow (see marker_edge_refinement.h).
    RefineMarkerCorners(gray, refinement, &quad);
    for (int c = 0; c < 4; ++c) detection.corners[c] = Eigen::Vector2d(quad[c].x + 0.5, quad[c].y + 0.5);
    markers.push_back(detection);
  }
  return markers;
}

bool InsideEnlargedQuad(const std::array<Eigen::Vector2d, 4>& quad, double factor,
                        const Eigen::Vector2d& xy) {
  const Eigen::Vector2d centroid = 0.25 * (quad[0] + quad[1] + quad[2] + quad[3]);
  // Inside a convex polygon: the same side of every edge. Scaling the quad
  // about the centroid is scaling the point by 1/factor instead.
  const Eigen::Vector2d p = centroid + (xy - centroid) / factor;
  int sign = 0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d e = quad[(i + 1) % 4] - quad[i];
    const Eigen::Vector2d d = p - quad[i];
    const double cross = e.x() * d.y() - e.y() * d.x();
    const int s = cross > 0 ? 1 : (cross < 0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

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
        const image_t image_id = images[i].image_id;
        const std::vector<MarkerDetection>& markers = detections[i];
        database.WriteMarkerDetections(image_id, markers);
        summary.num_markers += static_cast<int64_t>(markers.size());
        const FeatureKeypoints keypoints = database.ReadKeypoints(image_id);
        const FeatureDescriptors descriptors = database.ReadDescriptors(image_id);
        if (static_cast<size_t>(descriptors.rows()) != keypoints.size()) {
          throw InputError(options.database_path + ": image '" + images[i].name + "' has " +
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
        summary.num_features_before += static_cast<int64_t>(keypoints.size());
        summary.num_features_kept += static_cast<int64_t>(kept.size());
        if (markers.empty()) {
          ++summary.num_without_markers;
          LOG(WARNING) << images[i].name << ": no " << options.dictionary
                       << " markers; all its features are removed";
        }
        if (kept.size() == keypoints.size()) return;  // unchanged: its matches stay valid
        FeatureKeypoints kept_keypoints;
        FeatureDescriptors kept_descriptors(static_cast<Eigen::Index>(kept.size()), 128);
        for (size_t r = 0; r < kept.size(); ++r) {
          kept_keypoints.push_back(keypoints[kept[r]]);
          kept_descriptors.row(static_cast<Eigen::Index>(r)) =
              descriptors.row(static_cast<Eigen::Index>(kept[r]));
        }
        database.WriteKeypoints(image_id, kept_keypoints);
        database.WriteDescriptors(image_id, kept_descriptors);
        database.DeleteMatchesOfImage(image_id);
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
