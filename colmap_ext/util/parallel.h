// Work over an index range on a few threads, with the first exception (or a
// cancel request) stopping the others and rethrown on the caller's thread.
#pragma once

#include <cstddef>
#include <functional>

namespace portcal {

// Calls body(i) for i in [0, n) on `num_threads` threads (the caller's
// included), items handed out one at a time.
void ParallelFor(size_t n, int num_threads, const std::function<void(size_t)>& body);

// Like ParallelFor, but `consume(i)` runs on the caller's thread in index
// order as soon as compute(i) is done, so results can be written (e.g. into
// a database transaction) and freed while later items are computed. At most
// `max_in_flight` items are computed ahead of the consumer.
void OrderedParallelFor(size_t n, int num_threads, size_t max_in_flight,
                        const std::function<void(size_t)>& compute,
                        const std::function<void(size_t)>& consume);

}  // namespace portcal
