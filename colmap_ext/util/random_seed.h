// Random choices (RANSAC samples) are made from a seed the user can set
// (`--random_seed`, as COLMAP's), so that the same images give the same
// calibration and a regression can be seen.
#pragma once

#include <cstdint>

namespace portcal {

// A generator state from a user's seed (>= 0): splitmix64's finaliser, so
// neighbouring seeds give unrelated streams, and never 0 (a multiply-with-
// carry generator such as OpenCV's stays at 0 from there).
inline uint64_t GeneratorState(int random_seed) {
  uint64_t z = static_cast<uint64_t>(random_seed) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return z == 0 ? 0x5eedULL : z;
}

}  // namespace portcal
