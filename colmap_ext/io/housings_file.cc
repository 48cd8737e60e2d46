// housings.txt (portcal's sidecar) and import of the refractive COLMAP
// fork's cameras.txt, whose lines carry the port after the camera:
//   CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] [FLATPORT|DOMEPORT PORT_PARAMS[]]
#include <fstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::vector<double> ParseParams(const std::vector<std::string>& tokens, size_t begin, size_t end,
                                const std::string& where) {
  std::vector<double> params;
  for (size_t i = begin; i < end; ++i) {
    params.push_back(ParseDouble(tokens[i], where));
  }
  return params;
}

}  // namespace

std::map<camera_t, Housing> ReadHousingsText(const fs::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open");
  std::map<camera_t, Housing> housings;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(line_number);
    const std::vector<std::string> tokens = SplitTokens(trimmed, " \t\r");
    if (tokens.size() < 2) {
      throw InputError(where + ": expected CAMERA_ID MODEL PARAMS");
    }
    const camera_t camera_id =
        static_cast<camera_t>(ParseInteger(tokens[0], where + " camera id", 0, 0xFFFFFFFELL));
    Housing housing =
        Housing::FromName(tokens[1], ParseParams(tokens, 2, tokens.size(), where), where);
    if (!housings.emplace(camera_id, std::move(housing)).second) {
      throw InputError(where + ": second housing for camera " + tokens[0]);
    }
  }
  return housings;
}

void WriteHousingsText(const std::map<camera_t, Housing>& housings, std::ostream& out) {
  out.precision(17);
  out << "# Housing list with one line of data per camera behind a port:\n"
      << "#   CAMERA_ID, MODEL, PARAMS[]\n"
      << "#   FLATPORT params: " << FlatPort::kParamsInfo << "\n"
      << "#   DOMEPORT params: " << DomePort::kParamsInfo << "\n"
      << "# Number of housings: " << housings.size() << "\n";
  for (const auto& [camera_id, housing] : housings) {
    out << camera_id << " " << housing.ModelName();
    for (const double param : housing.params) out << " " << param;
    out << "\n";
  }
}

void ImportRefractiveCamerasText(const fs::path& path, std::map<camera_t, Camera>* cameras,
                                 std::map<camera_t, Housing>* housings) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open");
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(line_number);
    const std::vector<std::string> tokens = SplitTokens(trimmed, " \t\r");
    if (tokens.size() < 4) {
      throw InputError(where + ": expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS");
    }
    Camera camera;
    camera.camera_id =
        static_cast<camera_t>(ParseInteger(tokens[0], where + " camera id", 0, 0xFFFFFFFELL));
    try {
      camera.model_id = CameraModelNameToId(tokens[1]);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    camera.width = ParseInteger(tokens[2], where + " width", 0, 1LL << 40);
    camera.height = ParseInteger(tokens[3], where + " height", 0, 1LL << 40);
    const size_t num_params = CameraModelNumParams(camera.model_id);
    const size_t params_end = 4 + num_params;
    if (tokens.size() < params_end) {
      throw InputError(where + ": camera model " + tokens[1] + " takes " +
                       std::to_string(num_params) + " parameters (" +
                       CameraModelParamsInfo(camera.model_id) + ")");
    }
    camera.params = ParseParams(tokens, 4, params_end, where);
    camera.Validate(where);
    if (tokens.size() > params_end) {
      (*housings)[camera.camera_id] = Housing::FromName(
          tokens[params_end], ParseParams(tokens, params_end + 1, tokens.size(), where), where);
    }
    if (!cameras->emplace(camera.camera_id, camera).second) {
      throw InputError(where + ": duplicate camera id " + tokens[0]);
    }
  }
}

}  // namespace portcal
