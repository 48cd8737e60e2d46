// The ids COLMAP's tables and models use, declared once.
#pragma once

#include <cstdint>

namespace portcal {

using image_t = uint32_t;
using image_pair_t = uint64_t;
using point2D_t = uint32_t;
using point3D_t = uint64_t;

}  // namespace portcal
