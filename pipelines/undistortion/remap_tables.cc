#include "pipelines/undistortion/remap_tables.h"

#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"

namespace portcal {

RemapTables ComputeRemapTables(const VirtualPinhole& pinhole, int num_threads,
                               ProgressSink& progress) {
  const int width = static_cast<int>(pinhole.pinhole.width),
            height = static_cast<int>(pinhole.pinhole.height);
  RemapTables tables;
  tables.map_x.create(height, width, CV_32FC1);
  tables.map_y.create(height, width, CV_32FC1);
  progress.Begin("remap rows of camera " + std::to_string(pinhole.pinhole.camera_id),
                 static_cast<size_t>(height));
  ParallelFor(static_cast<size_t>(height), num_threads, [&](size_t row) {
    const int r = static_cast<int>(row);
    float* xs = tables.map_x.ptr<float>(r);
    float* ys = tables.map_y.ptr<float>(r);
    for (int c = 0; c < width; ++c) {
      // COLMAP's coordinates of the pixel's centre in, OpenCV's out.
      const std::optional<Eigen::Vector2d> source =
          pinhole.SourcePixel(Eigen::Vector2d(c + 0.5, r + 0.5));
      xs[c] = source ? static_cast<float>(source->x() - 0.5) : -1.0f;
      ys[c] = source ? static_cast<float>(source->y() - 0.5) : -1.0f;
    }
    progress.Advance(1);
  });
  progress.End();
  return tables;
}

cv::Mat ApplyRemapTables(const RemapTables& tables, const cv::Mat& image,
                         const cv::Size& source_size) {
  if (image.size() != source_size) {
    throw InputError("the image is " + std::to_string(image.cols) + " x " +
                     std::to_string(image.rows) + " px, its camera " +
                     std::to_string(source_size.width) + " x " +
                     std::to_string(source_size.height));
  }
  cv::Mat output;
  cv::remap(image, output, tables.map_x, tables.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  return output;
}

void WriteRemapTables(const RemapTables& tables, const VirtualPinhole& pinhole,
                      const std::filesystem::path& path) {
  const std::filesystem::path temporary = path.parent_path() / (".tmp-" + path.filename().string());
  try {
    cv::FileStorage storage(temporary.string(), cv::FileStorage::WRITE);
    if (!storage.isOpened()) throw InputError(path.string() + ": cannot be written");
    const std::vector<double>& p = pinhole.pinhole.params;
    const cv::Matx33d camera_matrix(p[0], 0, p[2] - 0.5, 0, p[1], p[3] - 0.5, 0, 0, 1);
    storage << "image_size" << cv::Size(tables.map_x.cols, tables.map_x.rows);
    // OpenCV's convention: the principal point with pixel centres at integers.
    storage << "camera_matrix" << cv::Mat(camera_matrix);
    storage << "source_size"
            << cv::Size(static_cast<int>(pinhole.source.camera.width),
                        static_cast<int>(pinhole.source.camera.height));
    storage << "design_depth" << pinhole.design_depth;
    storage << "map_x" << tables.map_x << "map_y" << tables.map_y;
    storage.release();
    std::filesystem::rename(temporary, path);
  } catch (const cv::Exception& e) {
    std::filesystem::remove(temporary);
    throw InputError(path.string() + ": " + e.what());
  } catch (...) {
    std::filesystem::remove(temporary);
    throw;
  }
}

}  // namespace portcal
