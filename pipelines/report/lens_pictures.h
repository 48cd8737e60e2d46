// Pictures of what a calibration says about the lens, as mrcal and OpenCV
// users look at it: are the residuals noise (a histogram against the fitted
// Gaussian), how far the lens is from a pinhole and where that was measured
// (the distortion map with the corners' region), and which parameters the
// views could not tell apart (the correlation matrix).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"

namespace portcal {

// The residuals' x and y components pooled (`residuals`, px) as a histogram
// over +-4 sigma, the Gaussian of standard deviation `sigma_px` (the fitted
// noise per axis) drawn over it, and in the title the share beyond 3 sigma
// against the Gaussian's 0.27 %.
cv::Mat ResidualHistogramPicture(const std::vector<Eigen::Vector2d>& residuals, double sigma_px,
                                 const std::string& title);

// |lens(p) - pinhole(p)| over the image (px): how far each pixel's ray
// lands from where a pinhole of the same fx, fy, cx, cy puts it, iso-lines
// at 1, 10 and 100 px, and the convex hull of `observed` (the corners: the
// region where the lens was measured, outside it extrapolated) in white.
cv::Mat DistortionPicture(const Camera& camera, const std::vector<Eigen::Vector2d>& observed);

// The correlation matrix of `covariance` over the parameters named `names`
// whose variance is positive (the held ones left out), each cell coloured by
// its value (blue -1, white 0, red +1) and labelled. Empty when fewer than
// two parameters were estimated.
cv::Mat CorrelationPicture(const Eigen::MatrixXd& covariance, const std::vector<std::string>& names,
                           const std::string& title);

}  // namespace portcal
