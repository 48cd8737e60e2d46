#include "colmap_ext/io/mrcal_model.h"

#include <Eigen/Geometry>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/npz_archive.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace portcal {
namespace {

// mrcal pixel = COLMAP pixel - 0.5 (both axes).
constexpr double kPixelShift = 0.5;

// mrcal.optimize()'s keyword arguments for `solve`, as an .npz archive
// (mrcal's own serialisation: None is stored as '').
std::string OptimizationInputsArchive(const MrcalLens& lens, const Camera& camera, const MrcalBoardSolve& solve) {
  const int64_t num_frames = static_cast<int64_t>(solve.frames_rt_toref.size());
  if (static_cast<int64_t>(solve.observations.size()) != num_frames * solve.height_n * solve.width_n * 3) {
    throw std::invalid_argument("MrcalBoardSolve: observations do not match the frames and the board");
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
  npz.AddDoubles("observations_board", {num_frames, solve.height_n, solve.width_n, 3}, solve.observations);
  npz.AddInt32s("indices_frame_camintrinsics_camextrinsics", {num_frames, 3}, indices);
  npz.AddString("observations_point", "");
  npz.AddString("indices_point_camintrinsics_camextrinsics", "");
  npz.AddString("lensmodel", lens.lensmodel);
  npz.AddInt32s("imagersizes", {1, 2}, {static_cast<int32_t>(camera.width), static_cast<int32_t>(camera.height)});
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

struct CameraModelDeleter {
  void operator()(mrcal_cameramodel_t* model) const { mrcal_free_cameramodel(&model); }
};

}  // namespace

std::string MrcalLensModelFor(const std::string& colmap_model) {
  if (colmap_model == "SIMPLE_PINHOLE" || colmap_model == "PINHOLE") return "LENSMODEL_PINHOLE";
  if (colmap_model == "SIMPLE_RADIAL" || colmap_model == "RADIAL" || colmap_model == "OPENCV") {
    return "LENSMODEL_OPENCV4";
  }
  if (colmap_model == "FULL_OPENCV") return "LENSMODEL_OPENCV8";
  // No exact counterpart in mrcal 2.2: name what comes closest.
  std::string nearest;
  if (colmap_model == "OPENCV_FISHEYE" || colmap_model == "SIMPLE_RADIAL_FISHEYE" ||
      colmap_model == "RADIAL_FISHEYE" || colmap_model == "THIN_PRISM_FISHEYE") {
    nearest = "LENSMODEL_SPLINED_STEREOGRAPHIC (or LENSMODEL_OPENCV8 for fields of view "
              "below ~100 deg, i.e. COLMAP's FULL_OPENCV)";
  } else if (colmap_model == "FOV") {
    nearest = "LENSMODEL_OPENCV8 (COLMAP's FULL_OPENCV)";
  } else {
    throw InputError("camera model " + colmap_model + " is not a COLMAP model (one of " +
                     CameraModelNames() + ")");
  }
  throw InputError("camera model " + colmap_model + " has no mrcal counterpart (mrcal 2.2); "
                   "nearest: " + nearest + ". Re-calibrate with that model to cross-check it");
}

std::string MrcalExtraFreedom(const std::string& colmap_model) {
  if (colmap_model == "SIMPLE_PINHOLE") return "fx != fy";
  if (colmap_model == "SIMPLE_RADIAL") return "fx != fy, k2, p1, p2";
  if (colmap_model == "RADIAL") return "fx != fy, p1, p2";
  return "";
}

std::vector<int> MrcalParamSources(const std::string& colmap_model) {
  const std::string lensmodel = MrcalLensModelFor(colmap_model);
  if (colmap_model == "SIMPLE_PINHOLE") return {0, 0, 1, 2};
  if (colmap_model == "SIMPLE_RADIAL") return {0, 0, 1, 2, 3, -1, -1, -1};
  if (colmap_model == "RADIAL") return {0, 0, 1, 2, 3, 4, -1, -1};
  // PINHOLE, OPENCV, FULL_OPENCV: the same order.
  const int n = lensmodel == "LENSMODEL_PINHOLE" ? 4 : lensmodel == "LENSMODEL_OPENCV4" ? 8 : 12;
  std::vector<int> sources(n);
  for (int i = 0; i < n; ++i) sources[i] = i;
  return sources;
}

MrcalLens MrcalLensFromCamera(const Camera& camera) {
  MrcalLens lens;
  lens.lensmodel = MrcalLensModelFor(camera.ModelName());
  for (const int source : MrcalParamSources(camera.ModelName())) {
    lens.intrinsics.push_back(source >= 0 ? camera.params[source] : 0.0);
  }
  lens.intrinsics[2] -= kPixelShift;
  lens.intrinsics[3] -= kPixelShift;
  return lens;
}

Camera CameraFromMrcalLens(const MrcalLens& lens, uint64_t width, uint64_t height,
                           const std::string& context) {
  std::vector<double> p = lens.intrinsics;
  std::string model;
  if (lens.lensmodel == "LENSMODEL_PINHOLE" && p.size() == 4) {
    model = "PINHOLE";
  } else if (lens.lensmodel == "LENSMODEL_OPENCV4" && p.size() == 8) {
    model = "OPENCV";
  } else if (lens.lensmodel == "LENSMODEL_OPENCV5" && p.size() == 9) {
    model = "FULL_OPENCV";
    p.resize(12, 0.0);  // k4 = k5 = k6 = 0: the rational term is 1
  } else if (lens.lensmodel == "LENSMODEL_OPENCV8" && p.size() == 12) {
    model = "FULL_OPENCV";
  } else if (lens.lensmodel == "LENSMODEL_OPENCV12") {
    throw InputError(context + ": " + lens.lensmodel + " (thin prism) has no COLMAP "
                     "counterpart; nearest: FULL_OPENCV (LENSMODEL_OPENCV8)");
  } else {
    throw InputError(context + ": mrcal lens model " + lens.lensmodel + " with " +
                     std::to_string(p.size()) + " intrinsics has no COLMAP counterpart (COLMAP "
                     "expresses LENSMODEL_PINHOLE, OPENCV4, OPENCV5 and OPENCV8)");
  }
  p[2] += kPixelShift;
  p[3] += kPixelShift;
  Camera camera;
  camera.model_id = CameraModelNameToId(model);
  camera.width = width;
  camera.height = height;
  camera.params = p;
  camera.Validate(context);
  return camera;
}

std::array<double, 6> RtFromRigid(const Rigid3d& b_from_a) {
  const Eigen::AngleAxisd aa(b_from_a.rotation.normalized());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  return {r[0], r[1], r[2], b_from_a.translation[0], b_from_a.translation[1], b_from_a.translation[2]};
}

namespace {

// Debian's libmrcal parses a .cameramodel without looking at its end: a
// truncated file (an unclosed string, a comment or list running to the end)
// makes it read past the buffer (found by fuzzing). So the text is first
// checked to be one complete Python dict literal -- strings closed, brackets
// matched, nothing after the closing brace -- before mrcal sees it.
void CheckCompleteDictLiteral(const std::string& text, const std::string& path) {
  const auto fail = [&](const std::string& what, size_t at) {
    throw InputError(path + ": not a complete mrcal .cameramodel (" + what + " at byte " + std::to_string(at) + ")");
  };
  std::string open;  // the brackets not yet closed
  bool seen_dict = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\0') fail("a NUL byte", i);
    if (c == '#') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (c == '\'' || c == '"') {
      size_t j = i + 1;
      while (j < text.size() && text[j] != c && text[j] != '\n') j += text[j] == '\\' ? 2 : 1;
      if (j >= text.size() || text[j] != c) fail("an unclosed string", i);
      i = j;
    } else if (c == '{' || c == '[' || c == '(') {
      if (open.empty() && (seen_dict || c != '{')) fail("text outside the dict", i);
      seen_dict = true;
      open += c == '{' ? '}' : c == '[' ? ']' : ')';
    } else if (c == '}' || c == ']' || c == ')') {
      if (open.empty() || open.back() != c) fail("an unmatched '" + std::string(1, c) + "'", i);
      open.pop_back();
    } else if (open.empty() && !std::isspace(static_cast<unsigned char>(c))) {
      fail("text outside the dict", i);
    }
  }
  if (!seen_dict) fail("no dict", 0);
  if (!open.empty()) fail("an unclosed bracket", text.size());
}

}  // namespace

MrcalCameraModelFile ReadMrcalCameraModel(const std::filesystem::path& path) {
  // Read here and parsed from a checked, NUL-terminated string: mrcal's
  // file reader parses an mmap of the file, which has no terminator.
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw InputError(path.string() + ": too large for a .cameramodel");
  }
  CheckCompleteDictLiteral(text, path.string());
  std::unique_ptr<mrcal_cameramodel_t, CameraModelDeleter> model(
      mrcal_read_cameramodel_string(text.c_str(), static_cast<int>(text.size())));
  if (!model) {
    throw InputError(path.string() + ": not a readable mrcal .cameramodel (mrcal's parser "
                     "rejected it; its message is above)");
  }
  const int num_params = mrcal_lensmodel_num_params(&model->lensmodel);
  char name[256];
  if (!mrcal_lensmodel_name(name, sizeof(name), &model->lensmodel)) {
    throw InputError(path.string() + ": unnamed mrcal lens model");
  }
  MrcalLens lens;
  lens.lensmodel = name;
  lens.intrinsics.assign(model->intrinsics, model->intrinsics + num_params);
  MrcalCameraModelFile file;
  file.camera = CameraFromMrcalLens(lens, model->imagersize[0], model->imagersize[1],
                                    path.string());
  const Eigen::Vector3d r(model->rt_cam_ref[0], model->rt_cam_ref[1], model->rt_cam_ref[2]);
  const double angle = r.norm();
  const Eigen::Quaterniond rotation =
      angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle))
                : Eigen::Quaterniond::Identity();
  file.cam_from_ref = Rigid3d(rotation, Eigen::Vector3d(model->rt_cam_ref[3], model->rt_cam_ref[4],
                                                        model->rt_cam_ref[5]));
  return file;
}

void WriteMrcalCameraModel(const Camera& camera, const Rigid3d& cam_from_ref,
                           const std::filesystem::path& path, const MrcalBoardSolve* solve) {
  // mrcal's own writer rounds to 6 decimals (distortion terms lose digits);
  // the format is a Python dict literal, written here at full precision and
  // read back by mrcal's parser in the tests.
  const MrcalLens lens = MrcalLensFromCamera(camera);
  const std::array<double, 6> rt = RtFromRigid(cam_from_ref);
  const std::vector<double> extrinsics(rt.begin(), rt.end());
  const auto list = [](std::ostream& out, const std::vector<double>& values) {
    out << "[ ";
    for (const double v : values) out << v << ", ";
    out << "]";
  };
  WriteFileAtomically(path, false, [&](std::ostream& out) {
    out << std::setprecision(17);
    out << "# generated by portcal (COLMAP " << camera.ModelName() << ")\n{\n"
        << "  'lensmodel':  '" << lens.lensmodel << "',\n  'intrinsics': ";
    list(out, lens.intrinsics);
    out << ",\n  'imagersize': [ " << camera.width << ", " << camera.height << " ],\n"
        << "  'extrinsics': ";
    list(out, extrinsics);
    out << ",\n";
    if (solve) {
      out << "  'icam_intrinsics': 0,\n"
          << "  # mrcal.optimize()'s inputs at portcal's solution (an .npz archive in base 85,\n"
          << "  # as mrcal stores them), for mrcal's uncertainty and diagnostic tools\n"
          << "  'optimization_inputs': b'" << EncodeBase85(OptimizationInputsArchive(lens, camera, *solve))
          << "',\n";
    }
    out << "}\n";
  });
}

}  // namespace portcal
