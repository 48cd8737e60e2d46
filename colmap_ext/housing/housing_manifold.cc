#include "colmap_ext/housing/housing_manifold.h"

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>
#include <ceres/sphere_manifold.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "colmap_ext/housing/housing_refinement.h"
#include "colmap_ext/util/error.h"

namespace portcal {

void SetHousingRefinement(const Housing& model, bool refine_position, double* housing,
                          ceres::Problem* problem) {
  const HousingRefinement refinement = model.Refinement();
  const int n = static_cast<int>(model.params.size());
  std::vector<bool> refined(static_cast<size_t>(n), false);
  for (int k : refinement.orientation) refined[static_cast<size_t>(k)] = true;
  if (refine_position) {
    for (int k : refinement.position) refined[static_cast<size_t>(k)] = true;
  }
  if (std::none_of(refined.begin(), refined.end(), [](bool r) { return r; })) {
    problem->SetParameterBlockConstant(housing);
    return;
  }
  if (refinement.orientation.empty()) {
    std::vector<int> held;
    for (int k = 0; k < n; ++k) {
      if (!refined[static_cast<size_t>(k)]) held.push_back(k);
    }
    problem->SetManifold(housing, new ceres::SubsetManifold(n, held));
  } else {
    // The unit vector leads the parameters (every port model with one).
    PORTCAL_CHECK(refinement.orientation == (std::vector<int>{0, 1, 2}));
    std::vector<int> held;
    for (int k = 3; k < n; ++k) {
      if (!refined[static_cast<size_t>(k)]) held.push_back(k - 3);
    }
    problem->SetManifold(
        housing, new ceres::ProductManifold<ceres::SphereManifold<3>, ceres::SubsetManifold>(
                     ceres::SphereManifold<3>(), ceres::SubsetManifold(n - 3, held)));
  }
  for (const HousingParamBound& bound : refinement.bounds) {
    if (std::isfinite(bound.lower))
      problem->SetParameterLowerBound(housing, bound.index, bound.lower);
    if (std::isfinite(bound.upper))
      problem->SetParameterUpperBound(housing, bound.index, bound.upper);
  }
}

}  // namespace portcal
