// A camera's housing at run time: model id and parameter vector, and the
// camera + housing projection used outside of Ceres.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing_refinement.h"

namespace portcal {

struct Housing {
  int model_id = 0;
  std::vector<double> params;

  // Throws InputError (prefixed by `context`) for unknown names or invalid
  // parameters.
  static Housing FromName(const std::string& model_name, std::vector<double> params,
                          const std::string& context);

  std::string ModelName() const;
  bool SameModel(const Housing& other) const { return model_id == other.model_id; }
  std::string ParamsInfo() const;
  // Throws InputError (prefixed by `context`): unknown model, wrong count,
  // non-finite values, normal not unit, camera outside the dome, ...
  void Validate(const std::string& context) const;
  // Validate, and a housing a user gives (an option, a calibration file)
  // whose lengths are in millimetres instead of metres (a dome radius of
  // 43 m) is an error that says so.
  void ValidateInput(const std::string& context) const;
  // Why a real housing would hardly have these valid parameters (the
  // model's own bounds of plausibility), or nullopt.
  std::optional<std::string> Implausibility() const;
  // Where the port sits, in words (the model's InWords).
  std::string InWords() const;
  // The model's answers for an adjustment (housing_refinement.h): what it
  // refines and within which bounds, whether the parameters sit at one.
  HousingRefinement Refinement() const;
  bool AtBound() const;
  // Where a housing calibration may start, given the refraction axis the
  // views show (the model's StartCandidates): the same model and constants.
  std::vector<Housing> StartCandidates(const Eigen::Vector3d& axis) const;
  // In-air focal length over the one the camera appears to have behind
  // the housing near the axis (1 where the housing does not magnify).
  double InAirFocalRatio() const;
};

struct Ray3d {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit
};

// Point in the camera frame -> pixel, through the housing if there is one.
// nullopt where the point cannot be seen (behind the camera, inside the
// housing, total internal reflection).
std::optional<Eigen::Vector2d> ProjectPoint(const Camera& camera, const Housing* housing,
                                            const Eigen::Vector3d& point_in_cam);

// Pixel -> ray in the camera frame: in water (origin on the outer surface) if
// there is a housing, else from the camera centre. nullopt where the pixel
// has no ray.
std::optional<Ray3d> UnprojectPixel(const Camera& camera, const Housing* housing,
                                    const Eigen::Vector2d& pixel);

}  // namespace portcal
