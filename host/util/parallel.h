// parallel_for: fn(i) for every i in [0, n) on the machine's hardware threads (the calling one
// among them), each thread taking the next index from a shared counter; for independent pieces of
// host work whose results go to slots of their own (mip chains of several images, the emission of
// many triangles), so that the order of the results does not depend on the threads. The first
// exception any fn throws is rethrown once every thread has stopped taking indices.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace wp {

// The threads parallel_for uses: the hardware's, at least 1.
inline unsigned host_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

template <class Fn>
void parallel_for(std::size_t n, Fn fn) {
  const std::size_t workers = std::min<std::size_t>(host_threads(), n);
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < n;) {
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;  // no more indices
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace wp
