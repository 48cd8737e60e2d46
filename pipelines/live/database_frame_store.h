// Where a live session keeps its frames: image files and database rows
// (DatabaseFrameStore), and the views an earlier session kept there.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "database/database.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/images/image_reader.h"
#include "pipelines/live/live_session.h"

namespace portcal {

// A live session's kept frames as image files below the image folder and
// rows of the database (image, camera, target detection): the files are
// moved into place first, then the rows are committed (a failed commit
// removes the files again).
class DatabaseFrameStore : public KeptFrameStore {
 public:
  // `folders`: each camera's folder below `image_path` ("" for one camera,
  // cam1 and cam2 for a rig); `readers`: each camera's import options.
  DatabaseFrameStore(Database* database, std::string image_path,
                     const TargetDetectorOptions& detector, std::vector<std::string> folders,
                     std::vector<ImageReaderOptions> readers);

  std::string Store(const std::vector<cv::Mat>& images,
                    const std::vector<TargetDetection>& detections) override;

  // The rows go; the files are renamed NAME.removed (no image extension, so
  // no later import sees them), not deleted.
  void Remove(const std::string& name) override;

  // The camera of each folder's kept frames (-1 before the first).
  std::vector<int> camera_ids() const;

 private:
  // A continued session is of the same board and camera model as the kept
  // views: refused at start, naming both, rather than a mixed database or
  // a failure at the first keep.
  void CheckContinues(const DatabaseImage& image) const;

  std::string ImageName(size_t camera, const std::string& name) const;

  std::filesystem::path WriteFrame(const cv::Mat& image, const std::string& name) const;

  std::string Kept() const;

  // live_NNNN.png after the highest such name in the folders or database.
  std::string NextName();

  Database* database_;
  std::string image_path_;
  std::string target_;
  std::vector<ImageReaderOptions> readers_;
  std::vector<std::string> folders_;
  SharedCameras shared_;
  int counter_ = 0;
};

// Views a previous session kept in this database (a continued session),
// with their corners' ids, so that hands-free capture does not keep them
// again; a rig's by the name its two images share.
std::vector<KeptView> ExistingViews(Database* database, const std::vector<std::string>& folders);

}  // namespace portcal
