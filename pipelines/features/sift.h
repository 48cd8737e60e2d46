// SIFT keypoints and descriptors stored the way COLMAP stores them:
// keypoints in COLMAP pixels with the affine shape (scale, orientation),
// descriptors L1-root normalised (RootSIFT, COLMAP's default) and quantised
// to uint8 as COLMAP's FeatureDescriptorsToUnsignedByte does (x 512,
// rounded, clamped to 255).
//
// The detector is OpenCV 4.6's SIFT (Lowe 2004). Its thresholds are COLMAP's
// defaults in OpenCV's units: COLMAP's peak_threshold 0.02/3 equals OpenCV's
// contrastThreshold 0.04 over 3 octave layers, edge_threshold 10 in both.
#pragma once

#include <opencv2/core.hpp>

#include "colmap_ext/feature/keypoint.h"

namespace portcal {

struct SiftExtractionOptions {
  int max_num_features = 8192;  // strongest responses kept
  int max_image_size = 3200;    // larger images are downscaled first
  // -1: the first octave is the image upsampled by 2 (Lowe's and COLMAP's
  // default). k >= 0: detection starts at the image downscaled by 2^k (the
  // image is reduced by 2^(k+1) and OpenCV's upsampled octave is used).
  int first_octave = -1;
  int octave_resolution = 3;         // scales per octave
  double peak_threshold = 0.02 / 3;  // COLMAP's units
  double edge_threshold = 10;
  double sigma = 1.6;
  void Check() const;  // throws OptionError naming --SiftExtraction.*
};

struct SiftFeatures {
  FeatureKeypoints keypoints;
  FeatureDescriptors descriptors;
};

// `gray`: 8-bit single channel. Deterministic for a given image.
SiftFeatures ExtractSift(const cv::Mat& gray, const SiftExtractionOptions& options);

// COLMAP's L1-root normalisation and uint8 quantisation of one float
// descriptor row (any positive scale).
void QuantizeRootSift(const float* descriptor, uint8_t* out);

}  // namespace portcal
