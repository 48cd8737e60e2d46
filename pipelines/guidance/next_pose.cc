#include "pipelines/guidance/next_pose.h"

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <random>

#include "colmap_ext/util/error.h"
#include "pipelines/guidance/calibration_unknowns.h"
#include "pipelines/synthetic/view_sampler.h"

namespace portcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool InView(const CalibrationUnknowns& unknowns, const TargetShape& target,
            const Rigid3d& cam_from_target, double margin) {
  const Camera& camera = unknowns.camera.camera;
  for (const Eigen::Vector3d& corner : target.outline) {
    const auto pixel = unknowns.camera.Project(cam_from_target * corner);
    if (!pixel || pixel->x() < margin || pixel->y() < margin ||
        pixel->x() > camera.width - margin || pixel->y() > camera.height - margin) {
      return false;
    }
  }
  return true;
}

// The target centred on the optical axis at distance d, turned by
// `rotation` about its centre.
Rigid3d Centred(const TargetShape& target, const Eigen::Quaterniond& rotation, double d) {
  return Rigid3d(rotation, Eigen::Vector3d(0, 0, d) - rotation * target.center);
}

ViewSamplingOptions SamplingOptions(const NextPoseOptions& options) {
  ViewSamplingOptions sampling;
  sampling.distance_min_m = options.distance_min_m;
  sampling.distance_max_m = options.distance_max_m;
  sampling.tilt_max_deg = options.tilt_max_deg;
  sampling.roll_max_deg = options.roll_max_deg;
  sampling.border_margin_px = options.border_margin_px;
  sampling.max_view_angle_deg = 85;
  sampling.visibility = "full";
  sampling.max_tries = 2000;
  return sampling;
}

// The opening sequence's turns of the target: facing the camera, then
// tilted about the horizontal and the vertical axis by min(tilt_max, 40 deg).
std::vector<Eigen::Quaterniond> OpeningRotations(const NextPoseOptions& options) {
  const double tilt = std::min(options.tilt_max_deg, 40.0) * kDeg;
  return {Eigen::Quaterniond::Identity(),
          Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX())),
          Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()))};
}

}  // namespace

void NextPoseOptions::Check() const {
  if (!(distance_min_m > 0)) throw OptionError("--Live.distance_range", distance_min_m, "> 0 m");
  if (!(distance_max_m >= distance_min_m)) {
    throw OptionError("--Live.distance_range", distance_max_m, ">= the minimum distance");
  }
  if (!(tilt_max_deg >= 0 && tilt_max_deg <= 80)) {
    throw OptionError("--Live.max_tilt_deg", tilt_max_deg, "[0, 80]");
  }
  if (!(roll_max_deg >= 0 && roll_max_deg <= 180)) {
    throw OptionError("--Live.max_roll_deg", roll_max_deg, "[0, 180]");
  }
  if (!(border_margin_px >= 0)) throw OptionError("--Live.margin_px", border_margin_px, ">= 0");
  // Each candidate is a covariance evaluation (milliseconds): 10^5 already
  // takes minutes per suggestion.
  if (num_candidates < 1 || num_candidates > 100000) {
    throw OptionError("--Live.num_candidates", num_candidates, "in [1, 100000]");
  }
  Uncertainty().Check();
}

ProjectionUncertaintyOptions NextPoseOptions::Uncertainty() const {
  ProjectionUncertaintyOptions result = uncertainty;
  if (result.working_distance_m <= 0)
    result.working_distance_m = 0.5 * (distance_min_m + distance_max_m);
  return result;
}

TargetShape TargetShape::FromPoints(const std::vector<Eigen::Vector3d>& points) {
  TargetShape shape;
  shape.points = points;
  if (points.empty()) return shape;
  Eigen::Vector3d low = points[0], high = points[0];
  for (const Eigen::Vector3d& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  shape.center = 0.5 * (low + high);
  shape.outline = {Eigen::Vector3d(low.x(), low.y(), 0), Eigen::Vector3d(high.x(), low.y(), 0),
                   Eigen::Vector3d(high.x(), high.y(), 0), Eigen::Vector3d(low.x(), high.y(), 0)};
  return shape;
}

std::vector<PoseSuggestion> OpeningPoses(const CalibrationUnknowns& unknowns,
                                         const TargetShape& target,
                                         const NextPoseOptions& options) {
  const std::vector<Eigen::Quaterniond> rotations = OpeningRotations(options);
  const char* const whys[] = {"opening 1/3: facing the camera, filling the image",
                              "opening 2/3: tilted about the horizontal axis",
                              "opening 3/3: tilted about the vertical axis"};
  std::vector<PoseSuggestion> poses;
  for (size_t turn = 0; turn < rotations.size(); ++turn) {
    const Eigen::Quaterniond& rotation = rotations[turn];
    const std::string why = whys[turn];
    const int steps = 60;
    for (int k = 0; k <= steps; ++k) {
      const double d =
          options.distance_min_m + (options.distance_max_m - options.distance_min_m) * k / steps;
      const Rigid3d pose = Centred(target, rotation, d);
      if (!InView(unknowns, target, pose, options.border_margin_px)) continue;
      PoseSuggestion suggestion;
      suggestion.cam_from_target = pose;
      suggestion.why = why;
      suggestion.opening = true;
      poses.push_back(suggestion);
      break;
    }
  }
  if (poses.size() < rotations.size()) {
    throw NumericalError(
        "next-pose guidance: the target does not fit in the image within --Live.distance_range [" +
        std::to_string(options.distance_min_m) + ", " + std::to_string(options.distance_max_m) +
        "] m; allow a larger distance");
  }
  return poses;
}

std::vector<PoseSuggestion> SuggestPoses(const CalibrationUnknowns& unknowns,
                                         const TargetShape& target,
                                         const CalibrationInformation& information, int num_kept,
                                         int count, const NextPoseOptions& options) {
  options.Check();
  unknowns.Check();
  const ProjectionUncertaintyModel model(unknowns, options.Uncertainty());
  // The opening only while it is not yet taken: past it, a range where
  // only tilted views fit is no error.
  const std::vector<PoseSuggestion> opening =
      num_kept < 3 ? OpeningPoses(unknowns, target, options) : std::vector<PoseSuggestion>();
  const ViewSamplingOptions sampling = SamplingOptions(options);
  CalibrationInformation current = information;
  std::vector<PoseSuggestion> suggestions;
  for (int step = 0; step < count; ++step) {
    const int index = num_kept + step;
    PoseSuggestion best;
    if (index < static_cast<int>(opening.size())) best = opening[static_cast<size_t>(index)];
    best.before = model.Evaluate(current);
    if (best.opening) {
      current += ViewInformation(unknowns, target.points, best.cam_from_target);
      best.after = model.Evaluate(current);
      suggestions.push_back(best);
      continue;
    }
    std::mt19937_64 rng(options.seed * 1000003ULL + static_cast<uint64_t>(index));
    double best_score = std::numeric_limits<double>::infinity();
    std::optional<CalibrationInformation> best_information;
    for (int c = 0; c < options.num_candidates; ++c) {
      Rigid3d pose;
      try {
        pose = SampleTargetView(unknowns.camera.camera, unknowns.camera.HousingOrNull(),
                                target.outline, target.center, -Eigen::Vector3d::UnitZ(), sampling,
                                &rng);
      } catch (const NumericalError&) {
        break;  // no pose fits: handled below
      }
      const CalibrationInformation added = ViewInformation(unknowns, target.points, pose);
      const ProjectionUncertainty after = model.Evaluate(current + added);
      // Undetermined counts as infinitely uncertain; ties (all undetermined)
      // go to the view adding the most information.
      const double score = after.determined ? after.mean_px : 1e12 / (1.0 + added.reduced.trace());
      if (score < best_score) {
        best_score = score;
        best.cam_from_target = pose;
        best.after = after;
        best_information = added;
      }
    }
    if (!best_information) {
      throw NumericalError(
          "next-pose guidance: no pose keeps the whole target in view within --Live.distance_range "
          "[" +
          std::to_string(options.distance_min_m) + ", " + std::to_string(options.distance_max_m) +
          "] m and --Live.max_tilt_deg " + std::to_string(options.tilt_max_deg));
    }
    best.why = "most lowers the expected projection uncertainty";
    current += *best_information;
    suggestions.push_back(best);
  }
  return suggestions;
}

namespace {

bool InBothViews(const RigUnknowns& rig, const TargetShape& target, const Rigid3d& cam1_from_target,
                 double margin) {
  return InView(rig.camera1, target, cam1_from_target, margin) &&
         InView(rig.camera2, target, rig.cam2_from_cam1 * cam1_from_target, margin);
}

// The rig's opening pose `index`: camera 1's opening rotation, the target
// centred between the two cameras' axes, as near as both see all of it.
std::optional<Rigid3d> RigOpeningPose(const RigUnknowns& rig, const TargetShape& target, int index,
                                      const NextPoseOptions& options) {
  const Eigen::Quaterniond rotation = OpeningRotations(options)[static_cast<size_t>(index)];
  const Eigen::Vector3d centre2_in_cam1 = rig.cam2_from_cam1.Inverse().translation;
  const Eigen::Vector3d shift(0.5 * centre2_in_cam1.x(), 0.5 * centre2_in_cam1.y(), 0);
  const int steps = 60;
  for (int k = 0; k <= steps; ++k) {
    const double d =
        options.distance_min_m + (options.distance_max_m - options.distance_min_m) * k / steps;
    Rigid3d pose = Centred(target, rotation, d);
    pose.translation += shift;
    if (InBothViews(rig, target, pose, options.border_margin_px)) return pose;
  }
  return std::nullopt;
}

// The worse camera's expected uncertainty with these informations;
// undetermined counts as infinitely uncertain, ties going to the most
// information added.
double RigScore(const ProjectionUncertainty& after1, const ProjectionUncertainty& after2,
                double added_trace) {
  if (!after1.determined || !after2.determined) return 1e12 / (1.0 + added_trace);
  return std::max(after1.mean_px, after2.mean_px);
}

}  // namespace

PoseSuggestion SuggestRigPose(const RigUnknowns& rig, const TargetShape& target,
                              const CalibrationInformation& information1,
                              const CalibrationInformation& information2, int num_kept,
                              const NextPoseOptions& options) {
  options.Check();
  rig.camera1.Check();
  rig.camera2.Check();
  const ProjectionUncertaintyModel model1(rig.camera1, options.Uncertainty());
  const ProjectionUncertaintyModel model2(rig.camera2, options.Uncertainty());
  const auto worse = [](const ProjectionUncertainty& a, const ProjectionUncertainty& b) {
    return !a.determined || (b.determined && a.mean_px >= b.mean_px) ? a : b;
  };
  PoseSuggestion best;
  best.before = worse(model1.Evaluate(information1), model2.Evaluate(information2));
  const char* openings[] = {"opening 1/3: facing the rig, between the cameras",
                            "opening 2/3: tilted about the horizontal axis",
                            "opening 3/3: tilted about the vertical axis"};
  if (num_kept < 3) {
    if (const auto pose = RigOpeningPose(rig, target, num_kept, options)) {
      best.cam_from_target = *pose;
      best.why = openings[num_kept];
      best.opening = true;
    }
  }
  const ViewSamplingOptions sampling = SamplingOptions(options);
  std::mt19937_64 rng(options.seed * 1000003ULL + static_cast<uint64_t>(num_kept));
  double best_score = std::numeric_limits<double>::infinity();
  for (int c = 0; c < (best.opening ? 0 : options.num_candidates); ++c) {
    Rigid3d pose;
    try {
      pose = SampleTargetView(rig.camera1.camera.camera, rig.camera1.camera.HousingOrNull(),
                              target.outline, target.center, -Eigen::Vector3d::UnitZ(), sampling,
                              &rng);
    } catch (const NumericalError&) {
      break;
    }
    if (!InBothViews(rig, target, pose, options.border_margin_px)) continue;
    const CalibrationInformation added1 = ViewInformation(rig.camera1, target.points, pose);
    const CalibrationInformation added2 =
        ViewInformation(rig.camera2, target.points, rig.cam2_from_cam1 * pose);
    const ProjectionUncertainty after1 = model1.Evaluate(information1 + added1);
    const ProjectionUncertainty after2 = model2.Evaluate(information2 + added2);
    const double score = RigScore(after1, after2, added1.reduced.trace() + added2.reduced.trace());
    if (score < best_score) {
      best_score = score;
      best.cam_from_target = pose;
      best.after = worse(after1, after2);
      best.why = "most lowers the rig's expected projection uncertainty";
    }
  }
  if (best.why.empty()) {
    throw NumericalError(
        "next-pose guidance: no pose keeps the whole target in both cameras' views within "
        "--Live.distance_range [" +
        std::to_string(options.distance_min_m) + ", " + std::to_string(options.distance_max_m) +
        "] m and --Live.max_tilt_deg " + std::to_string(options.tilt_max_deg));
  }
  if (best.opening) {
    best.after = worse(
        model1.Evaluate(information1 +
                        ViewInformation(rig.camera1, target.points, best.cam_from_target)),
        model2.Evaluate(information2 + ViewInformation(rig.camera2, target.points,
                                                       rig.cam2_from_cam1 * best.cam_from_target)));
  }
  return best;
}

PoseDistance DistanceToSuggestion(const CalibrationUnknowns& unknowns, const TargetShape& target,
                                  const Rigid3d& cam_from_target, const Rigid3d& suggested) {
  // A rectangular target held turned by 180 deg about its normal looks the
  // same to the person (and a detector may number it so): the nearer of
  // the two counts.
  const Eigen::Quaterniond half_turn(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  const Rigid3d turned_from_target(half_turn, target.center - half_turn * target.center);
  PoseDistance best;
  best.outline_px = std::numeric_limits<double>::infinity();
  for (const Rigid3d& aim : {suggested, suggested * turned_from_target}) {
    PoseDistance distance;
    int count = 0;
    for (const Eigen::Vector3d& corner : target.outline) {
      const auto a = unknowns.camera.Project(cam_from_target * corner);
      const auto b = unknowns.camera.Project(aim * corner);
      if (!a || !b) continue;
      distance.outline_px += (*a - *b).norm();
      ++count;
    }
    distance.outline_px =
        count > 0 ? distance.outline_px / count : std::numeric_limits<double>::infinity();
    distance.rotation_deg = cam_from_target.rotation.angularDistance(aim.rotation) / kDeg;
    distance.translation_m = (cam_from_target * target.center - aim * target.center).norm();
    if (distance.outline_px < best.outline_px) best = distance;
  }
  return best;
}

}  // namespace portcal
