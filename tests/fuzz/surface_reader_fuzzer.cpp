// Fuzz target for the surface readers and the validation step. The first byte picks the file
// format, the rest is the file. Any partet::Error is an expected rejection; anything else (a
// crash, another exception, a sanitizer report, a hang, huge memory) is a finding.
// Built with libFuzzer by scripts/fuzz.sh; with PARTET_FUZZ_STANDALONE it is a plain program that
// replays files (the regression corpus in tests/fuzz/corpus) and runs as a unit test.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "partet/errors.hpp"
#include "io/read_surface.hpp"
#include "stages/validate.hpp"

namespace {

const std::string& scratch_dir() {
  static const std::string dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("partet_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".off", ".obj", ".ply", ".stl"};
  const std::string path = scratch_dir() + "/input" + kExtensions[data[0] % 4];
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const partet::SurfaceMesh surface = partet::read_surface(path);
    partet::validate_topology(surface);
    partet::check_no_self_intersections(surface);
    (void)partet::enclosed_volume(surface);
  } catch (const partet::Error&) {
    // a clean rejection
  }
  return 0;
}

#ifdef PARTET_FUZZ_STANDALONE
int main(int argc, char** argv) {
  int replayed = 0;
  for (int i = 1; i < argc; ++i) {
    for (const auto& entry : std::filesystem::directory_iterator(argv[i])) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ++replayed;
    }
  }
  std::filesystem::remove_all(scratch_dir());
  std::printf("replayed %d inputs without a crash or an unexpected exception\n", replayed);
  return replayed > 0 ? 0 : 1;
}
#endif
