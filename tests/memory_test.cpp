// What a cgroup allows: a Slurm job's memory limit (cgroup v2, or v1's memory controller) lowers
// what partet counts as available (the check's memory, the one-piece fallback, TetGen alone for
// a comparison). Cgroup trees are made in a temporary directory, as the kernel lays them out.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/memory.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

constexpr double kMB = 1048576.0;

void put(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

std::string bytes(double mb) { return std::to_string(static_cast<long long>(mb * kMB)) + "\n"; }

TEST(CgroupMemory, AV2LimitIsItsLimitLessWhatIsUsedButInactivePageCache) {
  const std::filesystem::path root = test::temp_dir("cgroup_v2");
  put(root / "job_7/memory.max", bytes(1000));
  put(root / "job_7/memory.current", bytes(600));
  put(root / "job_7/memory.stat", "anon 1\ninactive_file " + bytes(100) + "active_file 5\n");
  put(root / "job_7/step_0/memory.max", "max\n");  // the step itself has no limit: the job's counts
  put(root / "job_7/step_0/memory.current", bytes(550));
  EXPECT_DOUBLE_EQ(cgroup_available_mb("0::/job_7/step_0\n", root.string()), 500);
  // A tighter level below wins.
  put(root / "job_7/step_0/memory.max", bytes(300));
  put(root / "job_7/step_0/memory.stat", "inactive_file 0\n");
  EXPECT_DOUBLE_EQ(cgroup_available_mb("0::/job_7/step_0\n", root.string()), 0);  // 550 used of 300: none left
  put(root / "job_7/step_0/memory.current", bytes(100));
  EXPECT_DOUBLE_EQ(cgroup_available_mb("0::/job_7/step_0\n", root.string()), 200);
}

TEST(CgroupMemory, AV1MemoryControllerLimitCountsAndItsUnlimitedAncestorsDoNot) {
  const std::filesystem::path root = test::temp_dir("cgroup_v1");
  const std::filesystem::path job = root / "memory/slurm/uid_0/job_9";
  put(job / "memory.limit_in_bytes", bytes(2048));
  put(job / "memory.usage_in_bytes", bytes(1024));
  put(job / "memory.stat", "cache 7\ninactive_file 1\ntotal_inactive_file " + bytes(512));
  put(root / "memory/slurm/memory.limit_in_bytes", "9223372036854771712\n");
  put(root / "memory/slurm/memory.usage_in_bytes", bytes(9000));
  const std::string self = "12:pids:/slurm/uid_0/job_9\n4:cpu,memory:/slurm/uid_0/job_9\n0::/\n";
  EXPECT_DOUBLE_EQ(cgroup_available_mb(self, root.string()), 1536);
}

TEST(CgroupMemory, NoLimitOrNoCgroupFilesIsNegative) {
  const std::filesystem::path root = test::temp_dir("cgroup_none");
  put(root / "memory/memory.limit_in_bytes", "9223372036854771712\n");
  put(root / "memory/memory.usage_in_bytes", bytes(100));
  EXPECT_LT(cgroup_available_mb("4:memory:/\n0::/\n", root.string()), 0);
  EXPECT_LT(cgroup_available_mb("0::/not/there\n", root.string()), 0);
  EXPECT_LT(cgroup_available_mb("", root.string()), 0);
  EXPECT_LT(cgroup_available_mb("garbage\n", root.string()), 0);
}

TEST(CgroupMemory, ThisProcessHasSomeMemoryAvailable) {
  const double available = available_memory_mb();
  EXPECT_GT(available, 0);
}

}  // namespace
}  // namespace partet
