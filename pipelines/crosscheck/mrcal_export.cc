#include "pipelines/crosscheck/mrcal_export.h"

#include <map>
#include <set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/crosscheck/mrcal_calibration.h"

namespace portcal {
namespace {

// mrcal holds parameters by group only (the core fx, fy, cx, cy; the
// distortions): which groups portcal held, or why_not where a held set is
// not a union of groups.
bool MrcalSelectionsOf(const CameraCalibrationSettings& settings, MrcalBoardSolve* solve,
                       std::string* why_not) {
  const std::set<std::string> fixed(settings.fixed_params.begin(), settings.fixed_params.end());
  std::set<std::string> rest = fixed;
  if (fixed.count("focal") && fixed.count("principal_point")) {
    solve->intrinsics_core_estimated = false;
    rest.erase("focal");
    rest.erase("principal_point");
  }
  if (fixed.count("extra")) {
    solve->intrinsics_distortions_estimated = false;
    rest.erase("extra");
  }
  if (rest.empty()) return true;
  std::string names;
  for (const std::string& name : rest) names += (names.empty() ? "" : ", ") + name;
  *why_not = "--Calibration.fixed_params held " + names +
             "; mrcal holds the core (focal and principal_point) or the distortions (extra) only";
  return false;
}

}  // namespace

std::optional<MrcalBoardSolve> MrcalBoardSolveOfCalibration(
    const std::vector<CalibrationView>& views, const CameraCalibrationResult& result,
    const CameraCalibrationSettings& settings, std::string* why_not) {
  PORTCAL_CHECK(why_not != nullptr);
  MrcalBoardSolve selections;
  if (!MrcalSelectionsOf(settings, &selections, why_not)) return std::nullopt;
  std::map<std::string, const CalibrationView*> by_name;
  for (const CalibrationView& view : views) by_name[view.image_name] = &view;
  std::vector<CalibrationView> kept;
  std::vector<Rigid3d> poses;
  for (const CalibratedView& view : result.views) {
    if (view.dropped) continue;
    const auto it = by_name.find(view.image_name);
    PORTCAL_CHECK(it != by_name.end());
    kept.push_back(*it->second);
    poses.push_back(view.cam_from_target);
  }
  MrcalBoardSolve solve;
  try {
    solve = MrcalBoardSolveOf(kept, poses, InferBoardGrid(kept));
  } catch (const InputError& error) {
    *why_not = error.what();
    return std::nullopt;
  }
  solve.intrinsics_core_estimated = selections.intrinsics_core_estimated;
  solve.intrinsics_distortions_estimated = selections.intrinsics_distortions_estimated;
  solve.warp_estimated = settings.estimate_board_warp;
  solve.calobject_warp = result.board_warp;
  for (const CalibrationView& view : kept) solve.image_paths.push_back(view.image_name);
  return solve;
}

std::filesystem::path WriteCalibrationCameraModel(const std::vector<CalibrationView>& views,
                                                  const CameraCalibrationResult& result,
                                                  const CameraCalibrationSettings& settings,
                                                  const std::filesystem::path& dir) {
  const std::string model = result.camera.ModelName();
  try {
    MrcalLensModelFor(model);
  } catch (const InputError& error) {
    LOG(INFO) << "no camera.cameramodel: " << error.what();
    return {};
  }
  std::string why_not;
  const std::optional<MrcalBoardSolve> solve =
      MrcalBoardSolveOfCalibration(views, result, settings, &why_not);
  if (!solve) {
    LOG(WARNING)
        << "camera.cameramodel carries no optimization_inputs (mrcal's uncertainty tools will "
        << "refuse it): " << why_not;
  } else if (!MrcalExtraFreedom(model).empty()) {
    LOG(INFO) << "camera.cameramodel: mrcal's tools evaluate " << model << " as "
              << MrcalLensModelFor(model) << ", which also frees " << MrcalExtraFreedom(model)
              << "; their uncertainties are those of that larger model";
  }
  const std::filesystem::path path = dir / "camera.cameramodel";
  WriteMrcalCameraModel(result.camera, Rigid3d(), path, solve ? &*solve : nullptr);
  return path;
}

}  // namespace portcal
