// parallel_for: every index once, whatever the number of threads; the first failure comes back.
// CpuLoan: a thread confined to one CPU gets the lent ones for the loan's lifetime (and so do the
// threads it starts meanwhile), then its own mask back.
// balanced_ranks: no rank ends with more than the average work plus one item.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <vector>

#include "common/balanced_ranks.hpp"
#include "common/parallel.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

// The seam chains' plan (largest first): each rank's work at most the average plus the largest
// item, every rank given work when there are as many items, and rank 0 (which hands them out)
// never given more items than another rank when all are the same size.
TEST(BalancedRanks, NoRankEndsWithMoreThanTheAveragePlusOneItem) {
  for (int ranks : {1, 2, 3, 4, 7})
    for (std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(5), std::size_t(63)}) {
      std::vector<std::size_t> sizes;
      for (std::size_t i = 0; i < count; ++i) sizes.push_back(1000 + (i * 7919) % 5000);
      std::sort(sizes.rbegin(), sizes.rend());
      const std::vector<int> rank_of = balanced_ranks(sizes, ranks);
      ASSERT_EQ(rank_of.size(), count);
      std::vector<std::size_t> load(static_cast<std::size_t>(ranks), 0), items(load.size(), 0);
      for (std::size_t i = 0; i < count; ++i) {
        ASSERT_GE(rank_of[i], 0);
        ASSERT_LT(rank_of[i], ranks);
        load[static_cast<std::size_t>(rank_of[i])] += sizes[i];
        ++items[static_cast<std::size_t>(rank_of[i])];
      }
      std::size_t total = 0;
      for (std::size_t l : load) total += l;
      for (int r = 0; r < ranks; ++r) {
        EXPECT_LE(load[r], total / static_cast<std::size_t>(ranks) + (count ? sizes.front() : 0)) << ranks << " ranks";
        if (count >= static_cast<std::size_t>(ranks)) EXPECT_GT(items[r], 0u) << "rank " << r << " of " << ranks;
      }
    }
  const std::vector<int> same = balanced_ranks(std::vector<std::size_t>(5, 10), 2);
  EXPECT_EQ(std::count(same.begin(), same.end(), 0), 2);  // (rank 1 takes the odd one)
}

TEST(ParallelFor, EveryIndexExactlyOnce) {
  for (unsigned threads : {1u, 2u, 3u, 8u})
    for (std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(5), std::size_t(10'000)}) {
      std::vector<std::atomic<int>> calls(count);
      parallel_for(count, threads, [&](std::size_t i) { ++calls[i]; });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(calls[i].load(), 1) << threads << " threads, index " << i;
    }
}

// Under an address-space limit with no room for another thread's stack (a tight ulimit -v), the
// work is still done, by the threads that could start.
TEST(ParallelFor, WithoutRoomForAnotherThreadTheWorkIsStillDone) {
  std::vector<std::atomic<int>> calls(1000);
  const pid_t pid = ::fork();
  if (pid == 0) {
    {
      const test::NoRoomForThreads no_room(2);
      if (!no_room.ok()) ::_exit(11);
      parallel_for(calls.size(), 8, [&](std::size_t i) { ++calls[i]; });
    }
    for (const auto& c : calls)
      if (c.load() != 1) ::_exit(12);
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "11: threads still start under the limit, 12: not every index once";
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

cpu_set_t this_threads_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(::sched_getaffinity(0, sizeof set, &set), 0);
  return set;
}

TEST(CpuLoan, LendsTheCpusThenGivesThemBack) {
  const cpu_set_t all = this_threads_cpus();
  if (CPU_COUNT(&all) < 2) GTEST_SKIP() << "needs a process allowed on 2 CPUs";
  int first = 0;
  while (!CPU_ISSET(first, &all)) ++first;
  // Run the test on a thread confined to one CPU, as mpirun's binding confines a rank.
  std::thread confined([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    ASSERT_EQ(::sched_setaffinity(0, sizeof one, &one), 0);
    {
      const CpuLoan loan(all);
      cpu_set_t during = this_threads_cpus();
      EXPECT_TRUE(CPU_EQUAL(&during, &all));
      EXPECT_EQ(usable_cpus(64), std::min(64u, static_cast<unsigned>(CPU_COUNT(&all))));
      cpu_set_t started;
      std::thread([&] { started = this_threads_cpus(); }).join();
      EXPECT_TRUE(CPU_EQUAL(&started, &all)) << "a thread started during the loan has the lent CPUs";
    }
    cpu_set_t after = this_threads_cpus();
    EXPECT_TRUE(CPU_EQUAL(&after, &one));
    {
      const CpuLoan nothing_new(one);  // lending what it has changes nothing
      cpu_set_t during = this_threads_cpus();
      EXPECT_TRUE(CPU_EQUAL(&during, &one));
    }
  });
  confined.join();
}

}  // namespace
}  // namespace partet
