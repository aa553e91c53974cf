#include "test_support.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

#include "common/memory.hpp"
#include "partet/errors.hpp"

namespace partet::test {

NoRoomForThreads::NoRoomForThreads(double room_mb) {
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>((virtual_size_mb() + room_mb) * 1024 * 1024);
  if (::setrlimit(RLIMIT_AS, &limit) != 0) return;
  try {
    while (holders_.size() < 100)
      holders_.emplace_back([this] {
        while (!release_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      });
  } catch (const std::system_error&) {
    ok_ = true;  // no thread starts any more
  }
}

NoRoomForThreads::~NoRoomForThreads() {
  release_ = true;
  for (std::thread& h : holders_) h.join();
}
namespace {

std::vector<std::filesystem::path>& created() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}

void remove_created() {
  std::error_code ec;
  for (const auto& d : created()) std::filesystem::remove_all(d, ec);
}

}  // namespace

std::string temp_dir(const std::string& name) {
  namespace fs = std::filesystem;
  static std::once_flag registered;
  // The list must exist before the handler is registered: statics are destroyed in the reverse
  // order of construction and atexit registration, so a list made later would be gone by the
  // time the handler ran, and every test left its directory behind.
  std::call_once(registered, [] {
    created();
    std::atexit(remove_created);
  });
  fs::path dir = fs::temp_directory_path() / ("partet_test_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  created().push_back(dir);
  return dir.string();
}

::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

std::string input_error(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError thrown)";
}

}  // namespace partet::test
