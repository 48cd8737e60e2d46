#include "pipelines/features/nearest_descriptors.h"

#include <algorithm>

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define PORTCAL_HAVE_AVX2_KERNEL 1
#endif

namespace portcal {
namespace {

constexpr int kDims = 128;

// The one update rule of both implementations: a strictly larger product
// replaces, so the first of equal products stays.
inline void Offer(float dot, int index, NearestDescriptors* nearest) {
  if (dot > nearest->best) {
    nearest->second = nearest->best;
    nearest->best = dot;
    nearest->index = index;
  } else if (dot > nearest->second) {
    nearest->second = dot;
  }
}

void Reset(Eigen::Index n1, Eigen::Index n2, std::vector<NearestDescriptors>* nearest1,
           std::vector<NearestDescriptors>* nearest2) {
  nearest1->assign(static_cast<size_t>(n1), NearestDescriptors());
  nearest2->assign(static_cast<size_t>(n2), NearestDescriptors());
}

#ifdef PORTCAL_HAVE_AVX2_KERNEL

#define PORTCAL_AVX2 __attribute__((target("avx2,fma")))

// Rows of the first set per tile, rows of the second per tile: 3 x 4
// accumulators plus 3 row vectors and 1 column vector fill the 16 ymm
// registers. The second set is walked in chunks that stay in the L1 cache
// (48 rows x 512 bytes) while every row of the first set passes them.
constexpr int kTileRows = 3;
constexpr int kTileCols = 4;
constexpr Eigen::Index kChunkCols = 48;

// The sum of the eight lanes, added in the same order as HorizontalSum4
// adds each of its four, so equal products come out equal in any tile.
PORTCAL_AVX2 inline float HorizontalSum(__m256 v) {
  const __m256 pairs = _mm256_hadd_ps(v, v);
  const __m256 quads = _mm256_hadd_ps(pairs, pairs);
  return _mm_cvtss_f32(_mm_add_ss(_mm256_castps256_ps128(quads), _mm256_extractf128_ps(quads, 1)));
}

// Four accumulators' sums as one vector (a, b, c, d).
PORTCAL_AVX2 inline __m128 HorizontalSum4(__m256 a, __m256 b, __m256 c, __m256 d) {
  const __m256 ab = _mm256_hadd_ps(a, b);
  const __m256 cd = _mm256_hadd_ps(c, d);
  const __m256 abcd = _mm256_hadd_ps(ab, cd);
  return _mm_add_ps(_mm256_castps256_ps128(abcd), _mm256_extractf128_ps(abcd, 1));
}

// Dot products of R rows at `a` with C rows at `b` (both 128 floats apart),
// then each offered to its row's and its column's nearest, rows and columns
// in increasing order. An offer is skipped when it cannot change anything
// (not above the current second best), which after the first few columns
// is almost every time.
template <int R, int C>
PORTCAL_AVX2 inline void Tile(const float* a, const float* b, int row0, int col0,
                              NearestDescriptors* nearest1, NearestDescriptors* nearest2) {
  __m256 acc[R][C];
  for (int r = 0; r < R; ++r) {
    for (int c = 0; c < C; ++c) acc[r][c] = _mm256_setzero_ps();
  }
  for (int k = 0; k < kDims; k += 8) {
    __m256 av[R];
    for (int r = 0; r < R; ++r) av[r] = _mm256_loadu_ps(a + r * kDims + k);
    for (int c = 0; c < C; ++c) {
      const __m256 bv = _mm256_loadu_ps(b + c * kDims + k);
      for (int r = 0; r < R; ++r) acc[r][c] = _mm256_fmadd_ps(av[r], bv, acc[r][c]);
    }
  }
  alignas(16) float dots[R][4];
  for (int r = 0; r < R; ++r) {
    if constexpr (C == 4) {
      _mm_store_ps(dots[r], HorizontalSum4(acc[r][0], acc[r][1], acc[r][2], acc[r][3]));
    } else {
      for (int c = 0; c < C; ++c) dots[r][c] = HorizontalSum(acc[r][c]);
    }
  }
  for (int r = 0; r < R; ++r) {
    NearestDescriptors& row = nearest1[row0 + r];
    float top = dots[r][0];
    for (int c = 1; c < C; ++c) top = std::max(top, dots[r][c]);
    if (!(top > row.second)) continue;
    for (int c = 0; c < C; ++c) Offer(dots[r][c], col0 + c, &row);
  }
  for (int c = 0; c < C; ++c) {
    NearestDescriptors& col = nearest2[col0 + c];
    float top = dots[0][c];
    for (int r = 1; r < R; ++r) top = std::max(top, dots[r][c]);
    if (!(top > col.second)) continue;
    for (int r = 0; r < R; ++r) Offer(dots[r][c], row0 + r, &col);
  }
}

// Runs Tile<R, C> for the run-time sizes of an edge tile.
template <int R>
PORTCAL_AVX2 inline void EdgeTile(int cols, const float* a, const float* b, int row0, int col0,
                                  NearestDescriptors* nearest1, NearestDescriptors* nearest2) {
  switch (cols) {
    case 1:
      Tile<R, 1>(a, b, row0, col0, nearest1, nearest2);
      break;
    case 2:
      Tile<R, 2>(a, b, row0, col0, nearest1, nearest2);
      break;
    case 3:
      Tile<R, 3>(a, b, row0, col0, nearest1, nearest2);
      break;
    default:
      Tile<R, 4>(a, b, row0, col0, nearest1, nearest2);
      break;
  }
}

template <int R>
PORTCAL_AVX2 void RowsAgainstChunk(const float* a, int row0, const float* b, Eigen::Index col_begin,
                                   Eigen::Index col_end, NearestDescriptors* nearest1,
                                   NearestDescriptors* nearest2) {
  Eigen::Index c = col_begin;
  for (; c + kTileCols <= col_end; c += kTileCols) {
    Tile<R, kTileCols>(a, b + c * kDims, row0, static_cast<int>(c), nearest1, nearest2);
  }
  if (c < col_end) {
    EdgeTile<R>(static_cast<int>(col_end - c), a, b + c * kDims, row0, static_cast<int>(c),
                nearest1, nearest2);
  }
}

PORTCAL_AVX2 void NearestAvx2(const float* a, Eigen::Index n1, const float* b, Eigen::Index n2,
                              NearestDescriptors* nearest1, NearestDescriptors* nearest2) {
  for (Eigen::Index col_begin = 0; col_begin < n2; col_begin += kChunkCols) {
    const Eigen::Index col_end = std::min(n2, col_begin + kChunkCols);
    Eigen::Index r = 0;
    for (; r + kTileRows <= n1; r += kTileRows) {
      RowsAgainstChunk<kTileRows>(a + r * kDims, static_cast<int>(r), b, col_begin, col_end,
                                  nearest1, nearest2);
    }
    if (n1 - r == 2)
      RowsAgainstChunk<2>(a + r * kDims, static_cast<int>(r), b, col_begin, col_end, nearest1,
                          nearest2);
    if (n1 - r == 1)
      RowsAgainstChunk<1>(a + r * kDims, static_cast<int>(r), b, col_begin, col_end, nearest1,
                          nearest2);
  }
}

bool CpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

#endif  // PORTCAL_HAVE_AVX2_KERNEL

}  // namespace

void FindNearestDescriptorsPortable(const UnitDescriptorRows& descriptors1,
                                    const UnitDescriptorRows& descriptors2,
                                    std::vector<NearestDescriptors>* nearest1,
                                    std::vector<NearestDescriptors>* nearest2) {
  const Eigen::Index n1 = descriptors1.rows(), n2 = descriptors2.rows();
  Reset(n1, n2, nearest1, nearest2);
  // Products in blocks of rows so that memory stays bounded for large
  // feature counts. The scan walks each column down (Eigen stores them
  // contiguously; a block's 1024 entries stay in cache).
  constexpr Eigen::Index kBlock = 1024;
  Eigen::MatrixXf dots;
  for (Eigen::Index start = 0; start < n1; start += kBlock) {
    const Eigen::Index rows = std::min(kBlock, n1 - start);
    dots.noalias() = descriptors1.middleRows(start, rows) * descriptors2.transpose();
    for (Eigen::Index c = 0; c < n2; ++c) {
      for (Eigen::Index r = 0; r < rows; ++r) {
        const float d = dots(r, c);
        Offer(d, static_cast<int>(c), &(*nearest1)[static_cast<size_t>(start + r)]);
        Offer(d, static_cast<int>(start + r), &(*nearest2)[static_cast<size_t>(c)]);
      }
    }
  }
}

bool FindNearestDescriptorsAvx2(const UnitDescriptorRows& descriptors1,
                                const UnitDescriptorRows& descriptors2,
                                std::vector<NearestDescriptors>* nearest1,
                                std::vector<NearestDescriptors>* nearest2) {
#ifdef PORTCAL_HAVE_AVX2_KERNEL
  if (!CpuHasAvx2()) return false;
  Reset(descriptors1.rows(), descriptors2.rows(), nearest1, nearest2);
  NearestAvx2(descriptors1.data(), descriptors1.rows(), descriptors2.data(), descriptors2.rows(),
              nearest1->data(), nearest2->data());
  return true;
#else
  return false;
#endif
}

void FindNearestDescriptors(const UnitDescriptorRows& descriptors1,
                            const UnitDescriptorRows& descriptors2,
                            std::vector<NearestDescriptors>* nearest1,
                            std::vector<NearestDescriptors>* nearest2) {
  if (!FindNearestDescriptorsAvx2(descriptors1, descriptors2, nearest1, nearest2)) {
    FindNearestDescriptorsPortable(descriptors1, descriptors2, nearest1, nearest2);
  }
}

}  // namespace portcal
