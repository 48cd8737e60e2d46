// The size of the reduced camera system of a bundle adjustment (the points
// eliminated by the Schur complement), by which the solver is chosen: a
// sparse factorisation of a survey's system stays affordable however many
// images it has, since each image sees only its neighbours.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <map>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

// The 6x6 blocks of the reduced camera system: one per free image and one
// per ordered pair of free images that see a common point of `point_blocks`.
size_t ReducedCameraSystemBlocks(const Reconstruction& reconstruction,
                                 const std::map<point3D_t, Eigen::Vector3d>& point_blocks,
                                 const std::function<bool(image_t)>& is_free);

}  // namespace portcal
