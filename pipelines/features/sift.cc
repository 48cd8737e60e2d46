#include "pipelines/features/sift.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/error.h"

namespace portcal {

namespace {
constexpr double kUpsamplingShift = 0.25;
}  // namespace

void SiftExtractionOptions::Check() const {
  if (max_num_features < 1) {
    throw OptionError("--SiftExtraction.max_num_features", max_num_features, ">= 1");
  }
  if (max_image_size < 16) {
    throw OptionError("--SiftExtraction.max_image_size", max_image_size, ">= 16");
  }
  if (first_octave < -1 || first_octave > 4) {
    throw OptionError("--SiftExtraction.first_octave", first_octave, "-1 ... 4");
  }
  if (octave_resolution < 1 || octave_resolution > 10) {
    throw OptionError("--SiftExtraction.octave_resolution", octave_resolution, "1 ... 10");
  }
  if (!(peak_threshold > 0)) {
    throw OptionError("--SiftExtraction.peak_threshold", peak_threshold, "> 0");
  }
  if (!(edge_threshold > 1)) {
    throw OptionError("--SiftExtraction.edge_threshold", edge_threshold, "> 1");
  }
  if (!(sigma > 0)) throw OptionError("--SiftExtraction.sigma", sigma, "> 0");
}

void QuantizeRootSift(const float* descriptor, uint8_t* out) {
  double l1 = 0;
  for (int k = 0; k < 128; ++k) l1 += std::abs(descriptor[k]);
  for (int k = 0; k < 128; ++k) {
    const double root = l1 > 0 ? std::sqrt(std::abs(descriptor[k]) / l1) : 0.0;
    out[k] = static_cast<uint8_t>(std::min(255.0, std::round(512.0 * root)));
  }
}

SiftFeatures ExtractSift(const cv::Mat& gray, const SiftExtractionOptions& options) {
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  // One scale factor for the image: max_image_size, then first_octave.
  double scale = 1.0;  // original pixels per working pixel
  const int max_side = std::max(gray.cols, gray.rows);
  if (max_side > options.max_image_size)
    scale = static_cast<double>(max_side) / options.max_image_size;
  scale *= std::pow(2.0, options.first_octave + 1);
  cv::Mat work = gray;
  if (scale != 1.0) {
    const cv::Size size(std::max(1, static_cast<int>(std::lround(gray.cols / scale))),
                        std::max(1, static_cast<int>(std::lround(gray.rows / scale))));
    cv::resize(gray, work, size, 0, 0, cv::INTER_AREA);
  }
  const double sx = static_cast<double>(gray.cols) / work.cols;
  const double sy = static_cast<double>(gray.rows) / work.rows;

  // OpenCV's contrastThreshold is divided by the number of layers and
  // halved inside; COLMAP's peak_threshold is the final threshold.
  const double contrast_threshold = 2.0 * options.peak_threshold * options.octave_resolution;
  cv::Ptr<cv::SIFT> sift =
      cv::SIFT::create(options.max_num_features, options.octave_resolution, contrast_threshold,
                       options.edge_threshold, options.sigma);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  sift->detectAndCompute(work, cv::noArray(), keypoints, descriptors);
  // OpenCV may return a few more than asked when responses tie; keep the
  // strongest, deterministically.
  if (static_cast<int>(keypoints.size()) > options.max_num_features) {
    std::vector<int> order(keypoints.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return keypoints[a].response > keypoints[b].response; });
    order.resize(options.max_num_features);
    std::sort(order.begin(), order.end());
    std::vector<cv::KeyPoint> kept;
    cv::Mat kept_descriptors(static_cast<int>(order.size()), descriptors.cols, descriptors.type());
    for (size_t r = 0; r < order.size(); ++r) {
      kept.push_back(keypoints[order[r]]);
      descriptors.row(order[r]).copyTo(kept_descriptors.row(static_cast<int>(r)));
    }
    keypoints.swap(kept);
    descriptors = kept_descriptors;
  }

  SiftFeatures features;
  features.keypoints.reserve(keypoints.size());
  features.descriptors.resize(static_cast<Eigen::Index>(keypoints.size()), 128);
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::KeyPoint& k = keypoints[i];
    // OpenCV 4.6 builds its first octave by upsampling 2x (pixel j of it
    // is centred at j/2 - 0.25 of the input) but reports j/2: every
    // keypoint is 0.25 px too far right and down (measured: a Gaussian
    // blob at (100, 100) comes out at (100.23, 100.23); OpenCV 4.8 added
    // enable_precise_upscale for this). Undo it, then shift from OpenCV's
    // integer pixel centres to COLMAP's +0.5, and scale the working image
    // grid back to the original's.
    const float x = static_cast<float>((k.pt.x - kUpsamplingShift + 0.5) * sx);
    const float y = static_cast<float>((k.pt.y - kUpsamplingShift + 0.5) * sy);
    // cv::KeyPoint::size is the diameter of the neighbourhood, 2 x the
    // scale COLMAP stores; angle in degrees.
    const float feature_scale = static_cast<float>(0.5 * k.size * 0.5 * (sx + sy));
    const float orientation = static_cast<float>(k.angle * M_PI / 180.0);
    features.keypoints.push_back(
        FeatureKeypoint::FromScaleOrientation(x, y, feature_scale, orientation));
    QuantizeRootSift(descriptors.ptr<float>(static_cast<int>(i)),
                     features.descriptors.data() + 128 * static_cast<Eigen::Index>(i));
  }
  return features;
}

}  // namespace portcal
