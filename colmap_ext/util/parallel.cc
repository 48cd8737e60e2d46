#include "colmap_ext/util/parallel.h"

#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "colmap_ext/util/progress.h"

namespace portcal {

void ParallelFor(size_t n, int num_threads, const std::function<void(size_t)>& body) {
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto worker = [&] {
    for (size_t i = next++; i < n; i = next++) {
      try {
        CancelFlag::ThrowIfRequested();
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads && static_cast<size_t>(t) < n; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

void OrderedParallelFor(size_t n, int num_threads, size_t max_in_flight,
                        const std::function<void(size_t)>& compute,
                        const std::function<void(size_t)>& consume) {
  if (max_in_flight < 1) max_in_flight = 1;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<char> done(n, 0);
  size_t next = 0;      // next index to hand out
  size_t consumed = 0;  // items consumed so far
  bool stop = false;
  std::exception_ptr error;

  const auto worker = [&] {
    while (true) {
      size_t i;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return stop || next >= n || next < consumed + max_in_flight; });
        if (stop || next >= n) return;
        i = next++;
      }
      try {
        CancelFlag::ThrowIfRequested();
        compute(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        stop = true;
        changed.notify_all();
        return;
      }
      std::lock_guard<std::mutex> lock(mutex);
      done[i] = 1;
      changed.notify_all();
    }
  };
  std::vector<std::thread> threads;
  const int workers = num_threads < 1 ? 1 : num_threads;
  for (int t = 0; t < workers; ++t) threads.emplace_back(worker);
  try {
    for (size_t i = 0; i < n; ++i) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return stop || done[i]; });
        if (stop) break;
      }
      consume(i);
      std::lock_guard<std::mutex> lock(mutex);
      consumed = i + 1;
      changed.notify_all();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!error) error = std::current_exception();
    stop = true;
    changed.notify_all();
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
    changed.notify_all();
  }
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace portcal
