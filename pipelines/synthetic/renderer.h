// Image formation: supersampled rays of a camera (+ housing) through a scene,
// box-filtered per pixel, then optics and water effects, noise, 8 bits.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/synthetic/scene.h"

namespace portcal {

struct ImageFormationOptions {
  int spp = 4;               // samples per pixel side: spp^2 per pixel at stratum centres, [1, 16]
  double blur_sigma_px = 0;  // Gaussian optical blur, px, >= 0
  double noise_sigma = 1.0;  // Gaussian noise, gray levels, >= 0
  PrintLevels levels;
  // Water (apply along the ray's path from the port's outer surface, or the
  // camera centre without a housing):
  double attenuation_per_m = 0;      // c in exp(-c L), >= 0
  double backscatter_gray = 0;       // veil level B of L -> infinity (Jaffe-McGlamery)
  double forward_scatter_per_m = 0;  // blends a blurred image in by 1 - exp(-b L), >= 0
  double forward_scatter_sigma_px = 2.0;
  double vignetting = 0;  // strength in [0, 1]: gray *= 1 - v + v cos^4(angle off axis)
  // Motion blur: camera velocity in its own frame during the exposure.
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  double exposure_s = 0;   // 0: no motion blur
  int motion_samples = 5;  // sub-frame poses, [1, 64]
  int num_threads = 2;

  bool HasWater() const { return attenuation_per_m > 0; }
  bool HasMotionBlur() const {
    return exposure_s > 0 && (velocity_m_s.norm() > 0 || angular_velocity_rad_s.norm() > 0);
  }
  void Check() const;  // throws OptionError naming the field
};

// The rays (in water behind a housing) of every sample position of a camera,
// computed once and reused for every image of the camera. Stored as float:
// 1e-7 relative, ~1e-4 px, far below what anti-aliasing resolves.
class RayMap {
 public:
  RayMap(const Camera& camera, const Housing* housing, int spp, int num_threads);
  int width() const { return width_; }
  int height() const { return height_; }
  int spp() const { return spp_; }
  // Sample s (0 .. spp^2-1) of pixel (col, row); false where the pixel has no
  // ray (total internal reflection, distortion not invertible).
  bool Ray(int col, int row, int s, Eigen::Vector3d* origin, Eigen::Vector3d* dir) const {
    const size_t i = (static_cast<size_t>(row) * width_ + col) * spp_ * spp_ + s;
    const float* r = &rays_[6 * i];
    if (std::isnan(r[3])) return false;
    *origin = Eigen::Vector3d(r[0], r[1], r[2]);
    *dir = Eigen::Vector3d(r[3], r[4], r[5]);
    return true;
  }
  // cos(angle of the pixel centre's air ray to the optical axis).
  float CosOffAxis(int col, int row) const { return cos_off_axis_[row * width_ + col]; }

 private:
  int width_, height_, spp_;
  std::vector<float> rays_;
  std::vector<float> cos_off_axis_;
};

// Offset within the pixel [0, 1)^2 of sample s of spp^2.
Eigen::Vector2d SampleOffset(int s, int spp);

// Renders one 8-bit image. `noise_seed` makes the noise (and only it)
// reproducible: same inputs, same bytes.
cv::Mat RenderImage(const RayMap& rays, const std::vector<PlacedObject>& objects,
                    const ImageFormationOptions& options, uint64_t noise_seed);

}  // namespace portcal
