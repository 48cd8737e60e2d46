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
#include "colmap_ext/io/mrcal_optimization_inputs.h"
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
    nearest =
        "LENSMODEL_SPLINED_STEREOGRAPHIC (or LENSMODEL_OPENCV8 for fields of view "
        "below ~100 deg, i.e. COLMAP's FULL_OPENCV)";
  } else if (colmap_model == "FOV") {
    nearest = "LENSMODEL_OPENCV8 (COLMAP's FULL_OPENCV)";
  } else {
    throw InputError("camera model " + colmap_model + " is not a COLMAP model (one of " +
                     CameraModelNames() + ")");
  }
  throw InputError("camera model " + colmap_model +
                   " has no mrcal counterpart (mrcal 2.2); "
                   "nearest: " +
                   nearest + ". Re-calibrate with that model to cross-check it");
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
    throw InputError(context + ": " + lens.lensmodel +
                     " (thin prism) has no COLMAP "
                     "counterpart; nearest: FULL_OPENCV (LENSMODEL_OPENCV8)");
  } else {
    throw InputError(context + ": mrcal lens model " + lens.lensmodel + " with " +
                     std::to_string(p.size()) +
                     " intrinsics has no COLMAP counterpart (COLMAP "
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
  return {
      r[0], r[1], r[2], b_from_a.translation[0], b_from_a.translation[1], b_from_a.translation[2]};
}

Rigid3d RigidFromRt(const double* rt) {
  const Eigen::Vector3d r(rt[0], rt[1], rt[2]);
  const double angle = r.norm();
  const Eigen::Quaterniond rotation = angle > 0
                                          ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle))
                                          : Eigen::Quaterniond::Identity();
  return Rigid3d(rotation, Eigen::Vector3d(rt[3], rt[4], rt[5]));
}

namespace {

// Debian's libmrcal parses a .cameramodel without looking at its end: a
// truncated file (an unclosed string, a comment or list running to the end)
// makes it read past the buffer (found by fuzzing). So the text is first
// checked to be one complete Python dict literal -- strings closed, brackets
// matched, nothing after the closing brace -- before mrcal sees it.
void CheckCompleteDictLiteral(const std::string& text, const std::string& path) {
  const auto fail = [&](const std::string& what, size_t at) {
    throw InputError(path + ": not a complete mrcal .cameramodel (" + what + " at byte " +
                     std::to_string(at) + ")");
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

// Where the value of the top-level `key` starts in a complete dict literal
// (after CheckCompleteDictLiteral), or npos: mrcal's C parser skips what it
// does not use, so the solve and icam_intrinsics are found here.
size_t TopLevelValue(const std::string& text, const std::string& key) {
  int depth = 0;
  char previous = 0;  // the last significant character outside strings
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '#') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (c == '\'' || c == '"') {
      size_t j = i + 1;
      while (j < text.size() && text[j] != c) j += text[j] == '\\' ? 2 : 1;
      const bool is_key = depth == 1 && (previous == '{' || previous == ',') &&
                          text.compare(i + 1, j - i - 1, key) == 0 && j - i - 1 == key.size();
      i = j;
      previous = c;
      if (is_key) {
        const size_t colon = text.find_first_not_of(" \t\r\n", j + 1);
        if (colon != std::string::npos && text[colon] == ':')
          return text.find_first_not_of(" \t\r\n", colon + 1);
      }
    } else if (!std::isspace(static_cast<unsigned char>(c))) {
      if (c == '{' || c == '[' || c == '(') ++depth;
      if (c == '}' || c == ']' || c == ')') --depth;
      previous = c;
    }
  }
  return std::string::npos;
}

// The optimization_inputs bytes literal (b'...') and icam_intrinsics.
void ReadSolveFields(const std::string& text, const std::string& path, MrcalCameraModelFile* file) {
  const size_t inputs = TopLevelValue(text, "optimization_inputs");
  if (inputs == std::string::npos) return;
  if (inputs + 2 >= text.size() || text[inputs] != 'b' ||
      (text[inputs + 1] != '\'' && text[inputs + 1] != '"')) {
    throw InputError(path + ": 'optimization_inputs' is not a bytes literal (b'...')");
  }
  const size_t end = text.find(text[inputs + 1], inputs + 2);  // base 85 has no quotes
  if (end == std::string::npos) throw InputError(path + ": 'optimization_inputs' is not closed");
  file->optimization_inputs_base85 = text.substr(inputs + 2, end - inputs - 2);
  const size_t icam = TopLevelValue(text, "icam_intrinsics");
  char* parsed_end = nullptr;
  const long value =
      icam == std::string::npos ? -1 : std::strtol(text.c_str() + icam, &parsed_end, 10);
  if (icam == std::string::npos || parsed_end == text.c_str() + icam || value < 0 ||
      value > 1000000) {
    throw InputError(
        path + ": 'optimization_inputs' without a valid 'icam_intrinsics' (mrcal requires one)");
  }
  file->icam_intrinsics = static_cast<int>(value);
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
    throw InputError(path.string() +
                     ": not a readable mrcal .cameramodel (mrcal's parser "
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
  file.camera =
      CameraFromMrcalLens(lens, model->imagersize[0], model->imagersize[1], path.string());
  file.cam_from_ref = RigidFromRt(model->rt_cam_ref);
  ReadSolveFields(text, path.string(), &file);
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
          << "  'optimization_inputs': b'"
          << EncodeBase85(MrcalOptimizationInputsArchive(lens, camera, *solve)) << "',\n";
    }
    out << "}\n";
  });
}

}  // namespace portcal
