// What an adjustment may refine of a housing, and the bounds that keep the
// refined parameters a housing. Each port type answers it
// (Port::Refinement), so the adjustment holds no knowledge of port models.
#pragma once

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace portcal {

struct HousingParamBound {
  int index = 0;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
};

struct HousingRefinement {
  // Three parameters forming a unit vector, refined on the sphere (a flat
  // port's normal); empty when the port has no orientation.
  std::vector<int> orientation;
  // Refined freely within `bounds`: where the port sits (a flat port's
  // distance, a dome's centre). Metric: it needs the scene's scale.
  std::vector<int> position;
  // The rest (thickness, radius, refractive indices) are the user's
  // constants.
  std::vector<HousingParamBound> bounds;
  std::string position_name;      // "port distance", "decentering"
  std::string bound_description;  // "port distance 0.1 mm", ...

  // Every refined parameter's index: the orientation's, then the position's.
  std::vector<int> Refined() const {
    std::vector<int> refined = orientation;
    refined.insert(refined.end(), position.begin(), position.end());
    return refined;
  }
  bool IsRefined(int index) const {
    const std::vector<int> refined = Refined();
    return std::find(refined.begin(), refined.end(), index) != refined.end();
  }
};

}  // namespace portcal
