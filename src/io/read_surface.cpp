// Reading triangle surfaces through CGAL's polygon soup IO, with one-line error messages.
//
// CGAL only reports success or failure, so when it fails on an ASCII OFF or OBJ file we scan
// the text ourselves to say what is wrong and where (truncation, NaN, index out of range).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "stages/geometry.hpp"
#include "io/plain_off.hpp"
#include "io/surface_format.hpp"
#include "partet/errors.hpp"
#include "io/read_surface.hpp"
#include "stages/polygon_triangulation.hpp"

namespace partet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polygon = std::vector<std::size_t>;
namespace fs = std::filesystem;

}  // namespace

std::string check_surface_path(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError("cannot open '" + path + "': no such file");
  if (fs::is_directory(status)) throw InputError("cannot open '" + path + "': is a directory");
  // A FIFO or a device would block or never end; only regular files are read.
  if (!fs::is_regular_file(status)) throw InputError("cannot read '" + path + "': not a regular file");
  const std::string ext = lowercase_extension(path);
  if (ext != "off" && ext != "obj" && ext != "ply" && ext != "stl")
    throw InputError("cannot read '" + path + "': unknown format '" +
                     (ext.empty() ? std::string("(no extension)") : "." + ext) + "' (supported: " + kSupportedFormats +
                     ")");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  return ext;
}

namespace {

// Whether the file starts with a UTF-8 byte order mark (as editors on Windows write them).
bool starts_with_byte_order_mark(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[3] = {};
  return in.read(head, 3) && std::string(head, 3) == "\xEF\xBB\xBF";
}

// CGAL's reader for the format, past a byte order mark (CGAL's own readers take the mark for
// content). Text formats only: a binary STL or PLY starts with no mark.
bool read_after_byte_order_mark(const std::string& path, const std::string& ext, std::vector<Kernel::Point_3>& points,
                                std::vector<Polygon>& polygons) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(3);
  if (ext == "off") return CGAL::IO::read_OFF(in, points, polygons);
  CGAL::IO::set_mode(in, CGAL::IO::ASCII);
  if (ext == "obj") return CGAL::IO::read_OBJ(in, points, polygons);
  if (ext == "ply") return CGAL::IO::read_PLY(in, points, polygons);
  return CGAL::IO::read_STL(in, points, polygons, CGAL::parameters::use_binary_mode(false));
}

// CGAL's reader, with its failures turned into one-line messages.
void read_soup(const std::string& path, const std::string& ext, std::vector<Point3>& points,
               std::vector<Polygon>& polygons) {
  const std::string format = format_name(ext);
  const std::string prefix = "cannot read '" + path + "': ";
  std::vector<Kernel::Point_3> cgal_points;
  bool ok = false;
  try {
    ok = starts_with_byte_order_mark(path) ? read_after_byte_order_mark(path, ext, cgal_points, polygons)
                                           : CGAL::IO::read_polygon_soup(path, cgal_points, polygons);
  } catch (const std::exception& e) {
    throw InputError(prefix + "not a valid " + format + " file (" + e.what() + ")");
  }
  if (!ok) {
    std::string problem;
    if (ext == "off") problem = diagnose_off(path);
    if (ext == "obj") problem = diagnose_obj(path);
    if (problem.empty()) problem = "not a valid " + format + " file (truncated or malformed?)";
    throw InputError(prefix + problem);
  }
  if (polygons.empty()) {
    // CGAL's ASCII STL reader stops quietly at the first facet it cannot parse.
    std::error_code ec;
    const bool stl_with_content = ext == "stl" && fs::file_size(path, ec) > 0;
    throw InputError(prefix + "the file contains no faces" + (stl_with_content ? " (truncated or malformed?)" : ""));
  }
  if (cgal_points.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError(prefix + "too many vertices (" + std::to_string(cgal_points.size()) + ")");
  points.reserve(cgal_points.size());
  for (const Kernel::Point_3& p : cgal_points) points.push_back({p.x(), p.y(), p.z()});
}

// Every index in range, every polygon with three or more corners, triangulated.
std::vector<Triangle> triangles_of(const std::string& path, const std::string& ext, const std::vector<Point3>& points,
                                   const std::vector<Polygon>& polygons) {
  const std::string prefix = "cannot read '" + path + "': ";
  std::vector<Triangle> triangles;
  triangles.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const Polygon& polygon = polygons[f];
    for (std::size_t index : polygon) {
      if (index < points.size()) continue;
      // CGAL's OBJ reader lets an index one past the end through, and has already turned
      // 1-based and negative indices into offsets; the file itself tells what was written.
      std::string problem = ext == "obj" ? diagnose_obj(path) : "";
      if (problem.empty())
        problem = "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) + ", but there are only " +
                  std::to_string(points.size()) + " vertices";
      throw InputError(prefix + problem);
    }
    if (polygon.size() < 3)
      throw InputError(prefix + "face " + std::to_string(f) + " has only " + std::to_string(polygon.size()) +
                       " corners");
    if (polygon.size() == 3) {
      triangles.push_back({static_cast<std::int32_t>(polygon[0]), static_cast<std::int32_t>(polygon[1]),
                           static_cast<std::int32_t>(polygon[2])});
    } else if (!triangulate_polygon(polygon, points, triangles)) {
      throw InputError(prefix + "face " + std::to_string(f) + " has " + std::to_string(polygon.size()) +
                       " corners and cannot be triangulated");
    }
  }
  return triangles;
}

}  // namespace

SurfaceMesh read_surface_general(const std::string& path) {
  const std::string ext = check_surface_path(path);
  std::error_code ec;
  check_declared_counts(path, ext, fs::file_size(path, ec));
  SurfaceMesh surface;
  std::vector<Polygon> polygons;
  read_soup(path, ext, surface.points, polygons);
  for (std::size_t v = 0; v < surface.points.size(); ++v) {
    const Point3& p = surface.points[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw InputError("cannot read '" + path + "': vertex " + std::to_string(v) + " has a non-finite coordinate " +
                       coordinates_text(p));
  }
  surface.triangles = triangles_of(path, ext, surface.points, polygons);
  return surface;
}

namespace {

// What tells whether a file changed: its identity, size and times.
struct FileState {
  struct stat st {};
  explicit FileState(const std::string& path) { ::stat(path.c_str(), &st); }
  bool operator==(const FileState& o) const {
    return st.st_ino == o.st.st_ino && st.st_dev == o.st.st_dev && st.st_size == o.st.st_size &&
           st.st_mtim.tv_sec == o.st.st_mtim.tv_sec && st.st_mtim.tv_nsec == o.st.st_mtim.tv_nsec &&
           st.st_ctim.tv_sec == o.st.st_ctim.tv_sec && st.st_ctim.tv_nsec == o.st.st_ctim.tv_nsec;
  }
};

SurfaceMesh read_any(const std::string& path) {
  if (check_surface_path(path) == "off")
    if (std::optional<SurfaceMesh> plain = read_plain_off(path)) return std::move(*plain);
  return read_surface_general(path);
}

}  // namespace

SurfaceMesh read_surface(const std::string& path) {
  const FileState before(path);
  std::optional<SurfaceMesh> surface;
  std::optional<InputError> error;
  try {
    surface = read_any(path);
  } catch (const InputError& e) {
    error = e;
  }
  // A file rewritten while it was read gives a mix of two files, or an error about neither.
  if (!(FileState(path) == before))
    throw InputError("cannot read '" + path + "': the file changed while it was being read (is another program " +
                     "writing it?); run again once it is complete");
  if (error) throw *error;
  return std::move(*surface);
}

}  // namespace partet
