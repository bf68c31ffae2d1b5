// parallel_for (host/util/parallel.h), which makes the mip chains and the emitters' means on the
// hardware threads: every index once, whatever the thread count; an exception from any index
// reaches the caller after the threads have stopped; and the order of results, written to slots of
// their own, is the sequential one.
#include <atomic>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "host/util/parallel.h"

namespace {

TEST(ParallelFor, EveryIndexOnce) {
  for (std::size_t n : {0u, 1u, 2u, 7u, 1000u}) {
    std::vector<std::atomic<int>> seen(n);
    wp::parallel_for(n, [&](std::size_t i) { seen[i].fetch_add(1); });
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i].load(), 1) << "n " << n << " i " << i;
  }
}

TEST(ParallelFor, ResultsInTheirSlots) {
  std::vector<std::size_t> out(4096);
  wp::parallel_for(out.size(), [&](std::size_t i) { out[i] = i * i; });
  for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], i * i);
}

TEST(ParallelFor, AnExceptionReachesTheCaller) {
  std::atomic<int> ran{0};
  EXPECT_THROW(wp::parallel_for(100,
                                [&](std::size_t i) {
                                  ran.fetch_add(1);
                                  if (i == 3) throw std::runtime_error("index 3");
                                }),
               std::runtime_error);
  EXPECT_GE(ran.load(), 4);  // indices are taken in order: 0..3 at least ran
}

}  // namespace
