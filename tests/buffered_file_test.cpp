// BufferedFile: the bytes written are exactly the text formatted, across many buffers handed to
// its writing thread; a failing write is reported with the name the user knows.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/vfs.h>
#include <sys/wait.h>
#include <unistd.h>
#include <atomic>
#include <chrono>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "common/memory.hpp"
#include "io/buffered_file.hpp"
#include "partet/errors.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string formatted(double value) {
  char text[64];
  return std::string(text, std::to_chars(text, text + sizeof text, value, std::chars_format::general, 17).ptr);
}

// Whether `dir` is on a local disk's filesystem, where large files are written around the page
// cache (buffered_file.hpp).
bool on_local_disk(const fs::path& dir) {
  struct statfs filesystem {};
  if (::statfs(dir.c_str(), &filesystem) != 0) return false;
  const auto type = static_cast<unsigned long>(filesystem.f_type);
  return type == 0xEF53 || type == 0x58465342 || type == 0x9123683E;  // ext4, XFS, btrfs
}

// How many of the file's pages are in the page cache.
std::size_t cached_pages(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  const auto size = static_cast<std::size_t>(fs::file_size(path));
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  std::vector<unsigned char> resident((size + page - 1) / page);
  EXPECT_EQ(::mincore(map, size, resident.data()), 0);
  ::munmap(map, size);
  std::size_t count = 0;
  for (unsigned char r : resident) count += r & 1;
  return count;
}

// The directories a test writes in: the temporary directory (a local disk here and in CI) and,
// where there is one, a tmpfs (which refuses direct writes).
std::vector<fs::path> test_directories() {
  std::vector<fs::path> dirs{fs::temp_directory_path()};
  if (fs::is_directory("/dev/shm")) dirs.emplace_back("/dev/shm");
  return dirs;
}

TEST(BufferedFile, ManyBuffersGiveExactlyTheTextFormatted) {
  for (const fs::path& dir : test_directories()) {
    SCOPED_TRACE(dir.string());
    const fs::path path = dir / ("partet_buffered_" + std::to_string(::getpid()));
    std::string expected;
    {
      BufferedFile out(path.string());
      // About 40 MB: many buffers, so the writing thread and the writeback hints are exercised.
      for (std::int64_t i = 0; i < 2'000'000; ++i) {
        const std::int64_t big = i * 4'000'000'007LL - 7;
        const double x = 1.0 / static_cast<double>(i + 3);
        out.integer(big), out.space(), out.real(x), out.space(), out.text("ab"), out.newline();
        expected += std::to_string(big) + ' ' + formatted(x) + " ab\n";
        if (i % 500'000 == 0) {  // a run longer than a buffer goes through in pieces
          const std::string run(9'000'000 + static_cast<std::size_t>(i % 7), static_cast<char>('a' + i % 26));
          out.bytes(run.data(), run.size());
          expected += run;
        }
      }
      EXPECT_EQ(out.writes_directly(), on_local_disk(dir));
      out.close();
    }
    // Written directly, the file is not in the page cache (but for its tail, which is not a
    // whole block); through the cache, it is.
    const std::size_t pages = fs::file_size(path) / 4096;
    if (on_local_disk(dir))
      EXPECT_LE(cached_pages(path), 2u) << "of " << pages;
    else
      EXPECT_GT(cached_pages(path), pages / 2);
    const std::string written = read_all(path);
    fs::remove(path);
    ASSERT_EQ(written.size(), expected.size());
    EXPECT_TRUE(written == expected);
  }
}

// Without room for the writing thread's stack (a tight ulimit -v) the caller writes each buffer
// itself: the same file.
TEST(BufferedFile, WithoutRoomForItsThreadTheCallerWrites) {
  const fs::path path = fs::temp_directory_path() / ("partet_buffered_alone_" + std::to_string(::getpid()));
  std::string expected;
  for (std::int64_t i = 0; i < 1'500'000; ++i) expected += std::to_string(i * 7919) + " x\n";  // about 12 MB: several buffers
  const pid_t pid = ::fork();
  if (pid == 0) {
    try {
      BufferedFile out(path.string());
      // Room for the second buffer (4 MB), not for a thread's stack (8 MB).
      const test::NoRoomForThreads no_room(6);
      if (!no_room.ok()) ::_exit(12);
      out.bytes(expected.data(), expected.size());
      out.close();
    } catch (...) {
      ::_exit(11);
    }
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "11: the write failed, 12: threads still start under the limit";
  EXPECT_TRUE(read_all(path) == expected);
  fs::remove(path);
}

TEST(BufferedFile, SmallFileIsWrittenAtClose) {
  const fs::path path = fs::temp_directory_path() / ("partet_buffered_small_" + std::to_string(::getpid()));
  {
    BufferedFile out(path.string());
    out.text("4 3 0 0\n");
    out.close();
  }
  EXPECT_EQ(read_all(path), "4 3 0 0\n");
  fs::remove(path);
}

TEST(BufferedFile, FullDiskNamesTheFileTheUserAskedFor) {
  for (std::size_t lines : {std::size_t(10), std::size_t(3'000'000)}) {  // written at close; by the thread
    BufferedFile out("/dev/full", "out/m.ele");
    try {
      for (std::size_t i = 0; i < lines; ++i) out.integer(static_cast<std::int64_t>(i)), out.newline();
      out.close();
      FAIL() << "a full disk was not reported";
    } catch (const OutputError& e) {
      EXPECT_NE(std::string(e.what()).find("cannot write 'out/m.ele': No space left on device"), std::string::npos)
          << e.what();
    }
  }
}

// Lines "i\n" for i in [0, n): about 6.9 MB for a million, more than one buffer.
std::string count_lines(BufferedFile& out, std::int64_t n) {
  std::string expected;
  for (std::int64_t i = 0; i < n; ++i) {
    out.integer(i), out.newline();
    expected += std::to_string(i) + '\n';
  }
  return expected;
}

TEST(BufferedFile, FilesClosedInTheBackgroundAreCompleteAfterFinish) {
  const fs::path dir = fs::temp_directory_path() / ("partet_background_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<std::string> expected;
  for (int f = 0; f < 3; ++f) {
    BufferedFile out((dir / std::to_string(f)).string());
    expected.push_back(count_lines(out, 1'000'000 + f));
    out.close_in_background();
  }
  finish_background_writes();
  for (int f = 0; f < 3; ++f) EXPECT_TRUE(read_all(dir / std::to_string(f)) == expected[f]) << "file " << f;
  fs::remove_all(dir);
}

TEST(BufferedFile, BackgroundFailureIsReportedByFinishAfterTheOthersEnd) {
  const fs::path path = fs::temp_directory_path() / ("partet_background_ok_" + std::to_string(::getpid()));
  std::string expected;
  {
    BufferedFile full("/dev/full", "out/m.node");
    count_lines(full, 300'000);  // one buffer, first written by the thread after close_in_background
    full.close_in_background();
    BufferedFile fine(path.string());
    expected = count_lines(fine, 1'000'000);
    fine.close_in_background();
  }
  try {
    finish_background_writes();
    FAIL() << "a full disk was not reported";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write 'out/m.node': No space left on device"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(read_all(path) == expected);  // written to the end before the failure was thrown
  fs::remove(path);
  EXPECT_NO_THROW(finish_background_writes());  // nothing is left pending
}

// A write that fails part-way through a directly written file (here a file size limit, which
// cuts a write short at an unaligned size and then refuses the next, as a full disk does) is
// reported with the name the user knows, and nothing hangs.
TEST(BufferedFile, FailureWhileWritingDirectlyNamesTheFile) {
  fs::path dir;
  for (const fs::path& candidate : {fs::temp_directory_path(), fs::current_path()})  // the build directory
    if (dir.empty() && on_local_disk(candidate)) dir = candidate;
  if (dir.empty()) GTEST_SKIP() << "neither the temporary nor the build directory is on a local disk's filesystem";
  const fs::path path = dir / ("partet_direct_limit_" + std::to_string(::getpid()));
  rlimit before{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &before), 0);
  rlimit limited = before;
  limited.rlim_cur = (std::size_t{10} << 20) + 1234;
  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limited), 0);
  std::string message;
  bool direct = false;
  try {
    BufferedFile out(path.string(), "out/m.ele");
    for (std::int64_t i = 0; i < 5'000'000; ++i) {
      out.integer(i), out.newline();
      direct = direct || out.writes_directly();
    }
    out.close();
  } catch (const OutputError& e) {
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, previous_handler);
  EXPECT_TRUE(direct);
  EXPECT_NE(message.find("cannot write 'out/m.ele': File too large"), std::string::npos) << message;
  EXPECT_EQ(fs::file_size(path), limited.rlim_cur);  // written up to the limit, none of it lost
  fs::remove(path);
}

TEST(BufferedFile, MissingDirectoryIsReportedAtOnce) {
  EXPECT_THROW(BufferedFile("/nonexistent_partet_dir/m.node", "m.node"), OutputError);
}

// A rank writing into a temporary rank 0 made must not create it again once a failed run has
// removed it: that would leave a file nobody removes.
TEST(BufferedFile, MustExistNeverCreatesTheFile) {
  const fs::path path = fs::temp_directory_path() / ("partet_buffered_exist_" + std::to_string(::getpid()));
  try {
    BufferedFile out(path.string(), "out/m_p0.vtu", /*must_exist=*/true);
    FAIL() << "a missing file was opened";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("'out/m_p0.vtu': No such file or directory"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  std::ofstream(path) << "previous text, longer than the new";
  {
    BufferedFile out(path.string(), "out/m_p0.vtu", /*must_exist=*/true);
    out.text("new");
    out.close();
  }
  EXPECT_EQ(read_all(path), "new");  // truncated, as a created file would be
  fs::remove(path);
}

}  // namespace
}  // namespace partet
