#include "pipelines/markers/aruco.h"

#include <algorithm>
#include <utility>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

const std::vector<std::pair<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME>>& Table() {
  using namespace cv::aruco;
  static const std::vector<std::pair<std::string, PREDEFINED_DICTIONARY_NAME>> kTable = {
      {"DICT_4X4_50", DICT_4X4_50},
      {"DICT_4X4_100", DICT_4X4_100},
      {"DICT_4X4_250", DICT_4X4_250},
      {"DICT_4X4_1000", DICT_4X4_1000},
      {"DICT_5X5_50", DICT_5X5_50},
      {"DICT_5X5_100", DICT_5X5_100},
      {"DICT_5X5_250", DICT_5X5_250},
      {"DICT_5X5_1000", DICT_5X5_1000},
      {"DICT_6X6_50", DICT_6X6_50},
      {"DICT_6X6_100", DICT_6X6_100},
      {"DICT_6X6_250", DICT_6X6_250},
      {"DICT_6X6_1000", DICT_6X6_1000},
      {"DICT_7X7_50", DICT_7X7_50},
      {"DICT_7X7_100", DICT_7X7_100},
      {"DICT_7X7_250", DICT_7X7_250},
      {"DICT_7X7_1000", DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", DICT_APRILTAG_36h11},
  };
  return kTable;
}

}  // namespace

std::vector<std::string> ArucoDictionaryNames() {
  std::vector<std::string> names;
  for (const auto& [name, id] : Table()) names.push_back(name);
  return names;
}

cv::Ptr<cv::aruco::Dictionary> ArucoDictionaryByName(const std::string& name) {
  for (const auto& [known, id] : Table()) {
    if (known == name) return cv::aruco::getPredefinedDictionary(id);
  }
  std::string names;
  for (const auto& known : ArucoDictionaryNames()) names += (names.empty() ? "" : ", ") + known;
  throw InputError("unknown ArUco dictionary '" + name + "' (expected one of " + names + ")");
}

void CheckArucoDictionaryOption(const std::string& option, const std::string& name) {
  const std::vector<std::string> known = ArucoDictionaryNames();
  if (std::find(known.begin(), known.end(), name) != known.end()) return;
  std::string names;
  for (const auto& each : known) names += (names.empty() ? "" : ", ") + each;
  throw OptionError(option, name, "an ArUco dictionary: " + names);
}

std::vector<uint8_t> ArucoMarkerModules(const cv::aruco::Dictionary& dictionary, int marker_id,
                                        int* modules_per_side) {
  if (marker_id < 0 || marker_id >= dictionary.bytesList.rows) {
    throw InputError("ArUco marker id " + std::to_string(marker_id) +
                     " is not in the dictionary (it has " +
                     std::to_string(dictionary.bytesList.rows) + " markers)");
  }
  const int n = dictionary.markerSize + 2;
  cv::Mat image;
  // One pixel per module, one module of black border.
  dictionary.drawMarker(marker_id, n, image, 1);
  std::vector<uint8_t> modules(n * n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) modules[r * n + c] = image.at<uint8_t>(r, c) > 127 ? 1 : 0;
  }
  *modules_per_side = n;
  return modules;
}

}  // namespace portcal
