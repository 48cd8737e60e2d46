#include "pipelines/stages/target_extractor.h"

#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <tuple>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "database/database.h"
#include "database/new_database_file.h"
#include "database/stage_run.h"
#include "pipelines/detection/detection_rows.h"

namespace fs = std::filesystem;

namespace portcal {

TargetDetectorOptions DetectorOptions(const TargetExtractorOptions& o) {
  TargetDetectorOptions detector;
  detector.type = o.target_type;
  detector.square_size_m = o.square_size_m;
  detector.chessboard = o.chessboard;
  detector.markers = o.markers;
  detector.precise_fit = true;  // stored corners are calibrated on
  return detector;
}

void TargetExtractorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "a directory of images");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
  reader.Check();
  DetectorOptions(*this).Check();
}

namespace {

// What one image gave, whatever the target.
struct ImageResult {
  std::string name;
  int width = 0, height = 0;
  bool readable = false;
  std::string skip_reason;  // why an image is not used: unreadable, too small
  TargetDetection detection;
};

std::string OptionsText(const TargetExtractorOptions& o) {
  std::ostringstream out;
  out << "image_path=" << o.image_path << "\nImageReader.camera_model=" << o.reader.camera_model
      << "\nImageReader.single_camera=" << o.reader.single_camera
      << "\nImageReader.single_camera_per_folder=" << o.reader.single_camera_per_folder
      << "\nImageReader.camera_params=" << o.reader.camera_params
      << "\nTarget.type=" << o.target_type << "\nTarget.cols=" << o.chessboard.cols
      << "\nTarget.rows=" << o.chessboard.rows << "\nTarget.square_size=" << o.square_size_m
      << "\n";
  return out.str();
}

// Images that are to share a camera (--ImageReader.single_camera, or
// single_camera_per_folder) must have its size: the first image of another
// size stops the run at once, before the others are detected.
class SharedSizes {
 public:
  explicit SharedSizes(const ImageReaderOptions& reader) : reader_(reader) {}

  void Check(const std::string& name, int width, int height) {
    if (!reader_.single_camera && !reader_.single_camera_per_folder) return;
    const std::string group = reader_.single_camera ? "" : fs::path(name).parent_path().string();
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto [it, inserted] = first_.try_emplace(group, name, width, height);
    const auto& [first_name, first_width, first_height] = it->second;
    if (inserted || (first_width == width && first_height == height)) return;
    throw InputError(name + ": " + std::to_string(width) + "x" + std::to_string(height) + ", but " +
                     first_name + " is " + std::to_string(first_width) + "x" +
                     std::to_string(first_height) +
                     (reader_.single_camera
                          ? " and --ImageReader.single_camera 1 gives them one camera"
                          : " and --ImageReader.single_camera_per_folder 1 gives them one camera"));
  }

 private:
  const ImageReaderOptions& reader_;
  std::mutex mutex_;
  std::map<std::string, std::tuple<std::string, int, int>> first_;
};

// Reads and detects every image on options.num_threads threads; the first
// error (or a cancel) stops them all and is rethrown.
std::vector<ImageResult> DetectAll(const TargetExtractorOptions& options,
                                   const std::vector<std::string>& names, ProgressSink& progress) {
  std::vector<ImageResult> results(names.size());
  SharedSizes sizes(options.reader);
  progress.Begin("target_extractor: images", names.size());
  ParallelFor(names.size(), options.num_threads, [&](size_t i) {
    ImageResult& result = results[i];
    result.name = names[i];
    const cv::Mat gray =
        cv::imread((fs::path(options.image_path) / names[i]).string(), cv::IMREAD_GRAYSCALE);
    result.skip_reason =
        gray.empty() ? "cannot read the image" : ImageSizeProblem(gray.cols, gray.rows);
    if (result.skip_reason.empty()) {
      result.readable = true;
      result.width = gray.cols;
      result.height = gray.rows;
      sizes.Check(names[i], gray.cols, gray.rows);
      result.detection = DetectTarget(gray, DetectorOptions(options));
    }
    progress.Advance(1);
  });
  progress.End();
  return results;
}

}  // namespace

TargetExtractorSummary RunTargetExtractor(const TargetExtractorOptions& options,
                                          ProgressSink& progress) {
  options.Check();
  StageRun run("target_extractor", OptionsText(options));
  const std::vector<std::string> names = ListImages(options.image_path);
  LOG(INFO) << "target_extractor: " << names.size() << " images, " << options.target_type;

  // What can fail without the images fails first: the database opens (a
  // directory, a corrupt file) and can be written (a lock held elsewhere).
  NewDatabaseFile new_file(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  { Transaction probe = database.BeginTransaction(); }

  // Detection in parallel, outside the database transaction.
  const std::vector<ImageResult> results = DetectAll(options, names, progress);

  // One transaction: images, cameras, observations, status, log.
  Transaction transaction = database.BeginTransaction();
  TargetExtractorSummary summary;
  SharedCameras shared_cameras;
  const std::string target = TargetDescriptionText(DetectorOptions(options));
  std::string first_reason;  // of the first image without the target
  for (const ImageResult& result : results) {
    if (!result.readable) {
      LOG(WARNING) << result.name << ": " << result.skip_reason << "; skipped";
      continue;
    }
    const image_t image_id = ImportImage(&database, options.reader, result.name, result.width,
                                         result.height, &shared_cameras);
    const TargetDetection& detection = result.detection;
    if (!detection.found) LOG(WARNING) << result.name << ": " << detection.reason;
    if (!detection.found && first_reason.empty())
      first_reason = result.name + ": " + detection.reason;
    if (detection.found && !detection.note.empty())
      LOG(INFO) << result.name << ": " << detection.note;
    WriteTargetDetection(&database, image_id, detection, target);
    ++summary.num_images;
    summary.num_found += detection.found;
    summary.num_points += static_cast<int64_t>(detection.points.size());
  }
  if (summary.num_images == 0) {
    // Success on nothing would leave a database with no image and a stage
    // logged as done.
    throw InputError(options.image_path + ": none of the " + std::to_string(names.size()) +
                     " image files could be read and used (unreadable, or under " +
                     std::to_string(kMinImageSide) + " px a side)");
  }
  if (summary.num_found == 0) {
    // Nothing done is not a success: the next stage would only say "run
    // target_extractor first". The transaction rolls back, a new database
    // file goes, an existing one is left as it was.
    std::string cause =
        options.target_type == "chessboard"
            ? "--Target.cols and --Target.rows count inner corners, not squares (a board of 9 x 7 "
              "squares has 8 x 6)"
            : "--Target.dictionary and the marker and square sizes must be the board's";
    throw InputError(options.image_path + ": the target (" + target +
                     ") was found in none of the " + std::to_string(summary.num_images) +
                     " images (" + first_reason + "); " + cause + "; --Target.type is " +
                     options.target_type);
  }
  run.Finish(&database, {{"images", summary.num_images},
                         {"found", summary.num_found},
                         {"points", summary.num_points}});
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  new_file.Keep();
  LOG(INFO) << "target_extractor: target found in " << summary.num_found << " of "
            << summary.num_images << " images, " << summary.num_points << " corners";
  return summary;
}

}  // namespace portcal
