// ASCII OFF output. %.17g round-trips every double, so a written surface reads back
// bit-identical. Writing goes to PATH.tmp first so that a failed write never leaves a
// truncated file under the final name.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>

#include "partet/errors.hpp"
#include "partet/surface_io.hpp"

namespace partet {

void write_off(const SurfaceMesh& surface, const std::string& path) {
  const std::string tmp_path = path + ".tmp";
  std::FILE* out = std::fopen(tmp_path.c_str(), "w");
  if (!out) throw OutputError("cannot write '" + path + "': " + std::strerror(errno));

  bool ok = std::fprintf(out, "OFF\n%zu %zu 0\n", surface.points.size(), surface.triangles.size()) > 0;
  for (const Point3& p : surface.points) {
    if (!ok) break;
    ok = std::fprintf(out, "%.17g %.17g %.17g\n", p[0], p[1], p[2]) > 0;
  }
  for (const Triangle& t : surface.triangles) {
    if (!ok) break;
    ok = std::fprintf(out, "3 %d %d %d\n", static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])) > 0;
  }
  int write_errno = ok ? 0 : errno;
  if (std::fclose(out) != 0 && ok) {
    ok = false;
    write_errno = errno;
  }
  if (!ok) {
    std::remove(tmp_path.c_str());
    throw OutputError("cannot write '" + path + "': " + std::strerror(write_errno));
  }

  std::error_code ec;
  std::filesystem::rename(tmp_path, path, ec);
  if (ec) {
    std::remove(tmp_path.c_str());
    throw OutputError("cannot write '" + path + "': " + ec.message());
  }
}

}  // namespace partet
