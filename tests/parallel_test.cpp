// parallel_for: every index once, whatever the number of threads; the first failure comes back.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "common/parallel.hpp"

namespace partet {
namespace {

TEST(ParallelFor, EveryIndexExactlyOnce) {
  for (unsigned threads : {1u, 2u, 3u, 8u})
    for (std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(5), std::size_t(10'000)}) {
      std::vector<std::atomic<int>> calls(count);
      parallel_for(count, threads, [&](std::size_t i) { ++calls[i]; });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(calls[i].load(), 1) << threads << " threads, index " << i;
    }
}

TEST(ParallelFor, FailureIsRethrownAfterAllThreadsStop) {
  std::atomic<int> running{0};
  EXPECT_THROW(parallel_for(1000, 4,
                            [&](std::size_t i) {
                              ++running;
                              if (i == 17) throw std::runtime_error("block 17");
                              --running;
                            }),
               std::runtime_error);
  EXPECT_EQ(running.load(), 1);  // only the failed call is still counted: every other one ended
}

TEST(ParallelFor, UsableCpusIsAtLeastOneAndAtMostTheCap) {
  EXPECT_GE(usable_cpus(), 1u);
  EXPECT_LE(usable_cpus(3), 3u);
}

}  // namespace
}  // namespace partet
