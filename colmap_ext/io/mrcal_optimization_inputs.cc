#include "colmap_ext/io/mrcal_optimization_inputs.h"

#include <cmath>
#include <map>

#include "colmap_ext/io/npz_archive.h"
#include "colmap_ext/io/npz_reader.h"
#include "colmap_ext/util/error.h"

namespace portcal {

// mrcal.optimize()'s keyword arguments for `solve`, as an .npz archive
// (mrcal's own serialisation: None is stored as '').
std::string MrcalOptimizationInputsArchive(const MrcalLens& lens, const Camera& camera,
                                           const MrcalBoardSolve& solve) {
  const int64_t num_frames = static_cast<int64_t>(solve.frames_rt_toref.size());
  if (static_cast<int64_t>(solve.observations.size()) !=
      num_frames * solve.height_n * solve.width_n * 3) {
    throw std::invalid_argument(
        "MrcalBoardSolve: observations do not match the frames and the board");
  }
  NpzArchive npz;
  npz.AddDoubles("intrinsics", {1, static_cast<int64_t>(lens.intrinsics.size())}, lens.intrinsics);
  npz.AddDoubles("extrinsics_rt_fromref", {0, 6}, {});
  std::vector<double> frames;
  std::vector<int32_t> indices;
  for (int64_t f = 0; f < num_frames; ++f) {
    frames.insert(frames.end(), solve.frames_rt_toref[f].begin(), solve.frames_rt_toref[f].end());
    indices.insert(indices.end(), {static_cast<int32_t>(f), 0, -1});
  }
  npz.AddDoubles("frames_rt_toref", {num_frames, 6}, frames);
  npz.AddString("points", "");
  npz.AddDoubles("observations_board", {num_frames, solve.height_n, solve.width_n, 3},
                 solve.observations);
  npz.AddInt32s("indices_frame_camintrinsics_camextrinsics", {num_frames, 3}, indices);
  npz.AddString("observations_point", "");
  npz.AddString("indices_point_camintrinsics_camextrinsics", "");
  npz.AddString("lensmodel", lens.lensmodel);
  npz.AddInt32s("imagersizes", {1, 2},
                {static_cast<int32_t>(camera.width), static_cast<int32_t>(camera.height)});
  if (solve.warp_estimated) {
    npz.AddDoubles("calobject_warp", {2}, {solve.calobject_warp.x(), solve.calobject_warp.y()});
  } else {
    npz.AddString("calobject_warp", "");
  }
  npz.AddBool("do_optimize_intrinsics_core", solve.intrinsics_core_estimated);
  npz.AddBool("do_optimize_intrinsics_distortions", solve.intrinsics_distortions_estimated);
  npz.AddBool("do_optimize_extrinsics", true);  // as mrcal-calibrate-cameras; no extrinsics here
  npz.AddBool("do_optimize_frames", true);
  npz.AddBool("do_optimize_calobject_warp", solve.warp_estimated);
  npz.AddDouble("calibration_object_spacing", solve.spacing);
  npz.AddBool("do_apply_outlier_rejection", false);
  npz.AddBool("do_apply_regularization", false);
  npz.AddBool("verbose", false);
  if (!solve.image_paths.empty()) npz.AddStrings("imagepaths", solve.image_paths);
  return npz.Bytes();
}

namespace {

// The optimization_inputs' arrays, each checked for its shape on access.
class SolveArrays {
 public:
  SolveArrays(std::map<std::string, NpyArray> arrays, std::string context)
      : arrays_(std::move(arrays)), context_(std::move(context)) {}

  bool Has(const std::string& name) const {
    const auto it = arrays_.find(name);
    return it != arrays_.end() && !it->second.IsNone();
  }
  // The array `name` (required) with `rank` dimensions, its last `tail`.
  const NpyArray& Get(const std::string& name, size_t rank, int64_t tail = -1) const {
    if (!Has(name)) throw InputError(context_ + ": optimization_inputs without '" + name + "'");
    const NpyArray& array = arrays_.at(name);
    if (array.shape.size() != rank || (tail >= 0 && rank > 0 && array.shape.back() != tail)) {
      throw InputError(context_ + ": optimization_inputs' '" + name + "' has an unexpected shape");
    }
    return array;
  }
  std::vector<double> FiniteDoubles(const std::string& name, size_t rank, int64_t tail = -1) const {
    std::vector<double> values = Get(name, rank, tail).Doubles(Where(name));
    for (const double value : values) {
      if (!std::isfinite(value))
        throw InputError(context_ + ": optimization_inputs' '" + name + "' is not finite");
    }
    return values;
  }
  bool Flag(const std::string& name, bool fallback) const {
    return Has(name) ? Get(name, 0).Doubles(Where(name))[0] != 0 : fallback;
  }
  std::string Where(const std::string& name) const {
    return context_ + ": optimization_inputs' '" + name + "'";
  }
  const std::string& context() const { return context_; }

 private:
  std::map<std::string, NpyArray> arrays_;
  std::string context_;
};

std::vector<Rigid3d> Poses(const std::vector<double>& rts) {
  std::vector<Rigid3d> poses;
  for (size_t i = 0; i + 6 <= rts.size(); i += 6) poses.push_back(RigidFromRt(&rts[i]));
  return poses;
}

}  // namespace

MrcalBoardSolve ReadMrcalBoardSolve(const MrcalCameraModelFile& file, const std::string& context) {
  if (file.optimization_inputs_base85.empty()) {
    throw InputError(context +
                     ": carries no optimization_inputs (write it with mrcal-calibrate-cameras or "
                     "portcal camera_calibrator to keep them)");
  }
  const SolveArrays arrays(ReadNpz(DecodeBase85(file.optimization_inputs_base85, context), context),
                           context);
  if (!arrays.Has("observations_board")) {
    throw InputError(context + ": its solve observed no calibration board (points only)");
  }
  const NpyArray& observed = arrays.Get("observations_board", 4, 3);
  const std::vector<double> observations = arrays.FiniteDoubles("observations_board", 4, 3);
  const std::vector<int64_t> indices = arrays.Get("indices_frame_camintrinsics_camextrinsics", 2, 3)
                                           .Integers(arrays.Where("indices"));
  const std::vector<Rigid3d> frames = Poses(arrays.FiniteDoubles("frames_rt_toref", 2, 6));
  const std::vector<Rigid3d> extrinsics =
      arrays.Has("extrinsics_rt_fromref")
          ? Poses(arrays.FiniteDoubles("extrinsics_rt_fromref", 2, 6))
          : std::vector<Rigid3d>();
  const int64_t num_observations = observed.shape[0];
  if (static_cast<int64_t>(indices.size()) != 3 * num_observations) {
    throw InputError(context +
                     ": optimization_inputs' indices do not match its board observations");
  }
  MrcalBoardSolve solve;
  solve.height_n = static_cast<int>(observed.shape[1]);
  solve.width_n = static_cast<int>(observed.shape[2]);
  solve.spacing = arrays.FiniteDoubles("calibration_object_spacing", 0)[0];
  if (!(solve.spacing > 0) || solve.width_n < 2 || solve.height_n < 2) {
    throw InputError(context +
                     ": optimization_inputs' board is not a grid of at least 2x2 corners with a "
                     "positive spacing");
  }
  const std::vector<std::string> paths =
      arrays.Has("imagepaths") ? arrays.Get("imagepaths", 1).Strings(arrays.Where("imagepaths"))
                               : std::vector<std::string>();
  const size_t per_board = static_cast<size_t>(solve.width_n) * solve.height_n * 3;
  for (int64_t i = 0; i < num_observations; ++i) {
    const int64_t frame = indices[3 * i], icam = indices[3 * i + 1], extrinsic = indices[3 * i + 2];
    if (frame < 0 || frame >= static_cast<int64_t>(frames.size()) || extrinsic < -1 ||
        extrinsic >= static_cast<int64_t>(extrinsics.size())) {
      throw InputError(context + ": optimization_inputs' board observation " + std::to_string(i) +
                       " names a frame or camera pose the solve does not have");
    }
    if (icam != file.icam_intrinsics) continue;
    const Rigid3d cam_from_ref = extrinsic < 0 ? Rigid3d() : extrinsics[extrinsic];
    solve.frames_rt_toref.push_back(RtFromRigid(cam_from_ref * frames[frame]));
    solve.observations.insert(solve.observations.end(), observations.begin() + i * per_board,
                              observations.begin() + (i + 1) * per_board);
    solve.image_paths.push_back(static_cast<int64_t>(paths.size()) == num_observations
                                    ? paths[i]
                                    : "frame " + std::to_string(frame) + " (observation " +
                                          std::to_string(i) + ")");
  }
  if (solve.frames_rt_toref.empty()) {
    throw InputError(context + ": camera " + std::to_string(file.icam_intrinsics) +
                     " (icam_intrinsics) observed no board in the solve");
  }
  // A warp that was held keeps no freedom for a joint solve to use.
  solve.warp_estimated =
      arrays.Has("calobject_warp") && arrays.Flag("do_optimize_calobject_warp", true);
  if (arrays.Has("calobject_warp")) {
    const std::vector<double> warp = arrays.FiniteDoubles("calobject_warp", 1, 2);
    solve.calobject_warp = Eigen::Vector2d(warp[0], warp[1]);
  }
  solve.intrinsics_core_estimated = arrays.Flag("do_optimize_intrinsics_core", true);
  solve.intrinsics_distortions_estimated = arrays.Flag("do_optimize_intrinsics_distortions", true);
  return solve;
}

}  // namespace portcal
