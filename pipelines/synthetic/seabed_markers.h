// ArUco markers lying on a survey's seabed, as a diver lays scale bars or
// coded targets at the start of a dive: printed plates (a marker and a white
// quiet zone of a quarter of its side) in a grid near the corner where the
// survey begins, so that only its first lines see them. Each plate rests on
// the relief: tilted to the seabed's normal at its centre and lifted just
// clear of the bumps under it. Their side is what the refinement's
// --Markers.side_length gives: a survey's scale without navigation.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pipelines/synthetic/scene.h"

namespace portcal {

struct SeabedMarkerOptions {
  int count = 0;                           // 0: none
  double side_m = 0.15;                    // the marker's black square, > 0
  double spacing_m = 1.5;                  // between the plates' centres, > side
  std::string dictionary = "DICT_4X4_50";  // ids 0 .. count-1
  void Check() const;                      // throws OptionError naming survey.markers.*
};

struct SeabedMarker {
  int id = 0;
  std::array<Eigen::Vector3d, 4> corners;  // world, cv::aruco's order (TL, TR, BR, BL of the print)
};

struct SeabedMarkers {
  std::unique_ptr<SceneObject> object;  // the plates, in the world frame
  std::vector<SeabedMarker> markers;
};

// The plates over `seabed`, the grid starting at the corner (area[0],
// area[2]) of the surveyed area [x0, x1, y0, y1].
SeabedMarkers PlaceSeabedMarkers(const SeabedMarkerOptions& options, const SeabedObject& seabed,
                                 const Eigen::Vector4d& area, const PrintLevels& levels);

}  // namespace portcal
