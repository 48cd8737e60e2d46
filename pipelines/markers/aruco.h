// ArUco dictionaries by name (OpenCV 4.6 contrib's predefined ones) and the
// bit pattern of a marker. OpenCV types stay inside pipelines/.
#pragma once

#include <opencv2/aruco.hpp>
#include <string>
#include <vector>

namespace portcal {

// "DICT_4X4_50" ... "DICT_APRILTAG_36h11". Throws InputError listing the
// names for an unknown one.
cv::Ptr<cv::aruco::Dictionary> ArucoDictionaryByName(const std::string& name);
std::vector<std::string> ArucoDictionaryNames();
// Throws an OptionError naming `option` when `name` is no known dictionary.
void CheckArucoDictionaryOption(const std::string& option, const std::string& name);

// The marker's modules including its one-module black border, row-major,
// (bits + 2)^2 entries: 1 white, 0 black. Row 0 is the top edge (top-left to
// top-right corner) of the printed marker. Throws InputError for an id the
// dictionary does not have.
std::vector<uint8_t> ArucoMarkerModules(const cv::aruco::Dictionary& dictionary, int marker_id,
                                        int* modules_per_side);

}  // namespace portcal
