// The ordered parallel loop: in order, errors propagated.
#include "colmap_ext/util/parallel.h"

#include <gtest/gtest.h>

#include <vector>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

TEST(Parallel, OrderedParallelForConsumesInOrderAndPropagatesErrors) {
  std::vector<int> computed(100, 0), order;
  OrderedParallelFor(
      100, 2, 4, [&](size_t i) { computed[i] = static_cast<int>(i) * 2; },
      [&](size_t i) {
        EXPECT_EQ(computed[i], static_cast<int>(i) * 2);
        order.push_back(static_cast<int>(i));
      });
  ASSERT_EQ(order.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(order[i], i);
  EXPECT_THROW(OrderedParallelFor(
                   50, 2, 4,
                   [](size_t i) {
                     if (i == 20) throw std::runtime_error("boom");
                   },
                   [](size_t) {}),
               std::runtime_error);
}

}  // namespace
}  // namespace portcal
