#include "pipelines/synthetic/renderer.h"

#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"

namespace portcal {

void ImageFormationOptions::Check() const {
  if (spp < 1 || spp > 16) throw OptionError("render.spp", spp, "[1, 16]");
  if (!(blur_sigma_px >= 0)) throw OptionError("render.blur_sigma", blur_sigma_px, ">= 0");
  if (!(noise_sigma >= 0)) throw OptionError("render.noise_sigma", noise_sigma, ">= 0");
  if (!(attenuation_per_m >= 0)) {
    throw OptionError("water.attenuation", attenuation_per_m, ">= 0 (1/m)");
  }
  if (!(forward_scatter_per_m >= 0)) {
    throw OptionError("water.forward_scatter", forward_scatter_per_m, ">= 0 (1/m)");
  }
  if (!(forward_scatter_sigma_px > 0)) {
    throw OptionError("water.forward_scatter_sigma_px", forward_scatter_sigma_px, "> 0");
  }
  if (!(vignetting >= 0 && vignetting <= 1)) {
    throw OptionError("vignetting", vignetting, "[0, 1]");
  }
  if (!(exposure_s >= 0)) throw OptionError("motion_blur.exposure", exposure_s, ">= 0 (s)");
  if (motion_samples < 1 || motion_samples > 64) {
    throw OptionError("motion_blur.samples", motion_samples, "[1, 64]");
  }
  if (num_threads < 1) throw OptionError("num_threads", num_threads, ">= 1");
}

Eigen::Vector2d SampleOffset(int s, int spp) {
  // Stratum centres of the spp x spp grid over the pixel [0, 1)^2 (a
  // box filter of the pixel's area, as the shared renders state).
  return {(s % spp + 0.5) / spp, (s / spp + 0.5) / spp};
}

RayMap::RayMap(const Camera& camera, const Housing* housing, int spp, int num_threads)
    : width_(static_cast<int>(camera.width)), height_(static_cast<int>(camera.height)), spp_(spp) {
  const size_t num_samples = static_cast<size_t>(width_) * height_ * spp * spp;
  rays_.assign(6 * num_samples, 0.0f);
  cos_off_axis_.assign(static_cast<size_t>(width_) * height_, 1.0f);
  ParallelFor(static_cast<size_t>(height_), num_threads, [&](size_t row_index) {
    const int row = static_cast<int>(row_index);
    for (int col = 0; col < width_; ++col) {
      for (int s = 0; s < spp * spp; ++s) {
        const Eigen::Vector2d pixel = Eigen::Vector2d(col, row) + SampleOffset(s, spp);
        const std::optional<Ray3d> ray = UnprojectPixel(camera, housing, pixel);
        float* r = &rays_[6 * ((static_cast<size_t>(row) * width_ + col) * spp * spp + s)];
        if (!ray) {
          r[3] = std::nanf("");
          continue;
        }
        for (int k = 0; k < 3; ++k) {
          r[k] = static_cast<float>(ray->origin[k]);
          r[3 + k] = static_cast<float>(ray->direction[k]);
        }
      }
      const auto centre = camera.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
      if (centre) cos_off_axis_[row * width_ + col] = static_cast<float>(1.0 / centre->norm());
    }
  });
}

namespace {

struct PreparedObject {
  const SceneObject* object;
  Eigen::Matrix3d rotation;  // object_from_cam
  Eigen::Vector3d translation;
};

// Motion during the exposure: the camera at time tau (relative to mid
// exposure) is displaced by v tau and rotated by w tau in its own frame, so
// objects appear moved by the inverse.
std::vector<std::vector<PreparedObject>> PrepareSubframes(const std::vector<PlacedObject>& objects,
                                                          const ImageFormationOptions& options) {
  const int n = options.HasMotionBlur() ? options.motion_samples : 1;
  std::vector<std::vector<PreparedObject>> subframes(n);
  for (int i = 0; i < n; ++i) {
    const double tau = n == 1 ? 0.0 : options.exposure_s * ((i + 0.5) / n - 0.5);
    const Eigen::Vector3d w = options.angular_velocity_rad_s * tau;
    const Rigid3d moved_from_cam(
        Eigen::Quaterniond(
            Eigen::AngleAxisd(w.norm(), w.norm() > 0 ? w.normalized() : Eigen::Vector3d::UnitZ())),
        options.velocity_m_s * tau);
    const Rigid3d cam_from_moved = moved_from_cam.Inverse();
    for (const PlacedObject& placed : objects) {
      const Rigid3d object_from_cam = (cam_from_moved * placed.cam_from_object).Inverse();
      subframes[i].push_back({placed.object, object_from_cam.rotation.toRotationMatrix(),
                              object_from_cam.translation});
    }
  }
  return subframes;
}

// One pixel's gray value (before noise) and the mean length of its rays'
// water paths (1e6 where no ray hit anything): the supersampled rays of
// every subframe traced through the objects.
struct ShadedPixel {
  float value = 0;
  float path_length = 0;
};

// t_near holds, per subframe and object, where the last ray that hit it
// did (0: none yet); the next sample, beside it, starts its search there.
ShadedPixel ShadePixel(const RayMap& rays,
                       const std::vector<std::vector<PreparedObject>>& subframes,
                       const ImageFormationOptions& options, double background, int col, int row,
                       std::vector<double>* t_near) {
  const int spp2 = options.spp * options.spp;
  double sum = 0, length_sum = 0;
  int num_lengths = 0;
  for (int s = 0; s < spp2; ++s) {
    Eigen::Vector3d origin, dir;
    if (!rays.Ray(col, row, s, &origin, &dir)) {
      sum += subframes.size() * options.levels.invalid;
      continue;
    }
    size_t near_index = 0;
    for (const auto& prepared : subframes) {
      double t_max = 1e300;
      Hit best;
      bool found = false;
      for (const PreparedObject& p : prepared) {
        Hit hit;
        double& near = (*t_near)[near_index++];
        if (p.object->IntersectNear(p.rotation * origin + p.translation, p.rotation * dir, t_max,
                                    near, &hit)) {
          near = hit.t;
          best = hit;
          t_max = hit.t;
          found = true;
        }
      }
      if (!found) {
        sum += background;
        continue;
      }
      double gray = best.gray;
      if (options.HasWater()) {
        // Direct signal attenuated, plus the backscatter veil that
        // builds up along the same path (Jaffe 1990, McGlamery 1980).
        const double transmission = std::exp(-options.attenuation_per_m * best.t);
        gray = gray * transmission + options.backscatter_gray * (1 - transmission);
      }
      sum += gray;
      length_sum += best.t;
      ++num_lengths;
    }
  }
  ShadedPixel pixel;
  pixel.value = static_cast<float>(sum / (spp2 * subframes.size()));
  if (options.vignetting > 0) {
    const double c = rays.CosOffAxis(col, row);
    pixel.value *= static_cast<float>(1 - options.vignetting + options.vignetting * c * c * c * c);
  }
  pixel.path_length = num_lengths > 0 ? static_cast<float>(length_sum / num_lengths) : 1e6f;
  return pixel;
}

// Noise added (seeded), rounded and clamped to 8 bits.
cv::Mat Quantise(const cv::Mat& image, double noise_sigma, uint64_t noise_seed) {
  cv::Mat out(image.rows, image.cols, CV_8UC1);
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      double value = image.at<float>(row, col);
      if (noise_sigma > 0) value += noise_sigma * noise(rng);
      out.at<uint8_t>(row, col) = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
    }
  }
  return out;
}

}  // namespace

cv::Mat RenderImage(const RayMap& rays, const std::vector<PlacedObject>& objects,
                    const ImageFormationOptions& options, uint64_t noise_seed) {
  options.Check();
  PORTCAL_CHECK(rays.spp() == options.spp);
  const int width = rays.width(), height = rays.height();
  const auto subframes = PrepareSubframes(objects, options);
  const double background =
      options.HasWater() ? options.backscatter_gray : options.levels.background;
  cv::Mat image(height, width, CV_32F), path_length(height, width, CV_32F);
  ParallelFor(static_cast<size_t>(height), options.num_threads, [&](size_t row_index) {
    const int row = static_cast<int>(row_index);
    std::vector<double> t_near(subframes.size() * objects.size(), 0.0);
    for (int col = 0; col < width; ++col) {
      const ShadedPixel pixel = ShadePixel(rays, subframes, options, background, col, row, &t_near);
      image.at<float>(row, col) = pixel.value;
      path_length.at<float>(row, col) = pixel.path_length;
    }
  });
  if (options.forward_scatter_per_m > 0) {
    // Small-angle forward scattering blurs more the longer the water path.
    cv::Mat blurred;
    cv::GaussianBlur(image, blurred, cv::Size(0, 0), options.forward_scatter_sigma_px);
    cv::Mat weight;
    cv::exp(-options.forward_scatter_per_m * path_length, weight);
    image = image.mul(weight) + blurred.mul(1.0 - weight);
  }
  if (options.blur_sigma_px > 0) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), options.blur_sigma_px);
  }
  return Quantise(image, options.noise_sigma, noise_seed);
}

}  // namespace portcal
