// mrcal's board warp: a planar target that sags by
//   z = wx (1 - u^2) + wy (1 - v^2),
// (u, v) the point's target coordinates scaled to [-1, 1] over the board's
// extent, so that (wx, wy) are the sag at the board's centre in metres.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace portcal {

// A target point's (u, v) over the board's extent (x min, x max, y min,
// y max).
inline Eigen::Vector2d BoardWarpUv(const Eigen::Vector3d& point,
                                   const Eigen::Vector4d& board_extent) {
  return Eigen::Vector2d(
      2 * (point.x() - board_extent[0]) / std::max(1e-12, board_extent[1] - board_extent[0]) - 1,
      2 * (point.y() - board_extent[2]) / std::max(1e-12, board_extent[3] - board_extent[2]) - 1);
}

// The sag (metres, along the board's normal) at (u, v) for warp (wx, wy).
template <typename T>
T BoardSag(const T* warp, const Eigen::Vector2d& uv) {
  return warp[0] * (1.0 - uv.x() * uv.x()) + warp[1] * (1.0 - uv.y() * uv.y());
}

}  // namespace portcal
