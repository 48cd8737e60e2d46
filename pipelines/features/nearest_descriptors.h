// The two nearest descriptors, by brute force, in both directions at once:
// for each row of one set its best and second-best rows of the other (for
// Lowe's ratio test) and the reverse (for the cross check). Unit rows, so
// "nearest" is the largest dot product.
//
// Almost all of matching's time is these n1 x n2 x 128 dot products. Two
// implementations give the same answer up to float rounding:
//  - portable: Eigen's blocked matrix product, then a scan of the products;
//  - AVX2 + FMA: tiles of 3 x 4 dot products kept in registers, each tile's
//    products checked against the current second-best ones as they come,
//    so no product matrix is written or scanned. Built for AVX2 by a target
//    attribute on its functions only and chosen at run time, so the binary
//    still runs on CPUs without it. (The project is not built with
//    -march=native: Debian's Ceres is not, and Eigen objects of different
//    alignment must not cross between them.)
// Both visit, for each row, the columns in increasing order and, for each
// column, the rows in increasing order, so equal products resolve alike
// (the first one wins).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace portcal {

struct NearestDescriptors {
  int index = -1;
  float best = -2, second = -2;  // dot products (larger is closer)
};

using UnitDescriptorRows = Eigen::Matrix<float, Eigen::Dynamic, 128, Eigen::RowMajor>;

// nearest1[i]: the best two rows of descriptors2 for row i of descriptors1;
// nearest2[j]: the best two rows of descriptors1 for row j of descriptors2.
// Resizes and overwrites both. Uses the AVX2 kernel where the CPU has it.
void FindNearestDescriptors(const UnitDescriptorRows& descriptors1,
                            const UnitDescriptorRows& descriptors2,
                            std::vector<NearestDescriptors>* nearest1,
                            std::vector<NearestDescriptors>* nearest2);

// The two implementations, for tests and benchmarks. The AVX2 one returns
// false, touching nothing, where the CPU lacks AVX2 or FMA.
void FindNearestDescriptorsPortable(const UnitDescriptorRows& descriptors1,
                                    const UnitDescriptorRows& descriptors2,
                                    std::vector<NearestDescriptors>* nearest1,
                                    std::vector<NearestDescriptors>* nearest2);
bool FindNearestDescriptorsAvx2(const UnitDescriptorRows& descriptors1,
                                const UnitDescriptorRows& descriptors2,
                                std::vector<NearestDescriptors>* nearest1,
                                std::vector<NearestDescriptors>* nearest2);

}  // namespace portcal
