// A housing's parameter block in a Ceres problem, refined as its model
// allows (HousingRefinement): the orientation on the sphere, the position
// (when `refine_position`) within the model's bounds, the rest held.
#pragma once

#include <ceres/problem.h>

#include "colmap_ext/housing/housing.h"

namespace portcal {

// `housing` gives the model (and the bounds that depend on its constants);
// `params` is the block in `problem`, already added.
void SetHousingRefinement(const Housing& housing, bool refine_position, double* params,
                          ceres::Problem* problem);

}  // namespace portcal
