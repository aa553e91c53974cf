// ASCII OFF output. 17 significant digits round-trip every double, so a written surface reads
// back bit-identical. Writing goes to PATH.tmp first so that a failed write never leaves a
// truncated file under the final name.
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "io/buffered_file.hpp"
#include "partet/errors.hpp"
#include "io/write_surface.hpp"

namespace partet {

void write_off(const SurfaceMesh& surface, const std::string& path) {
  const std::string tmp_path = path + ".tmp";
  try {
    BufferedFile out(tmp_path, path);
    out.text("OFF\n");
    out.integer(static_cast<std::int64_t>(surface.points.size()));
    out.space();
    out.integer(static_cast<std::int64_t>(surface.triangles.size()));
    out.text(" 0\n");
    for (const Point3& p : surface.points) {
      out.real(p[0]);
      out.space();
      out.real(p[1]);
      out.space();
      out.real(p[2]);
      out.newline();
    }
    for (const Triangle& t : surface.triangles) {
      out.text("3");
      for (auto v : t) {
        out.space();
        out.integer(v);
      }
      out.newline();
    }
    out.close();
  } catch (const OutputError&) {
    std::remove(tmp_path.c_str());
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(tmp_path, path, ec);
  if (ec) {
    std::remove(tmp_path.c_str());
    throw OutputError("cannot write '" + path + "': " + ec.message());
  }
}

}  // namespace partet
