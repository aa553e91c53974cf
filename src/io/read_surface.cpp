// Reading triangle surfaces through CGAL's polygon soup IO, with one-line error messages.
//
// CGAL only reports success or failure, so when it fails on an ASCII OFF or OBJ file we scan
// the text ourselves to say what is wrong and where (truncation, NaN, index out of range).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "partet/surface_io.hpp"

namespace partet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polygon = std::vector<std::size_t>;

const char* const kSupportedFormats = ".off, .obj, .ply, .stl";

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string format_name(const std::string& ext) {
  std::string name = ext;
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return name;
}

std::string coordinates_text(const Kernel::Point_3& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

// Splits text into lines with '#' comments removed, keeping 1-based line numbers.
struct TextLine {
  std::size_t number;
  std::string text;
};

std::vector<TextLine> content_lines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<TextLine> lines;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r\n") == std::string::npos) continue;
    lines.push_back({number, line});
  }
  return lines;
}

std::vector<std::string> tokens_of(const std::string& text) {
  std::istringstream in(text);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

// strtod accepts "nan" and "inf" (unlike operator>>), which is what lets us name them.
std::optional<double> parse_double(const std::string& token) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  double value = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return std::nullopt;
  return value;
}

std::optional<long long> parse_integer(const std::string& token) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  long long value = std::strtoll(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE) return std::nullopt;
  return value;
}

// Returns what is wrong with an ASCII OFF file, or an empty string if we cannot tell.
std::string diagnose_off(const std::string& path) {
  std::vector<TextLine> lines = content_lines(path);
  if (lines.empty()) return "the file is empty";
  std::vector<std::string> header = tokens_of(lines[0].text);
  const std::string& keyword = header[0];
  if (keyword.size() < 3 || keyword.compare(keyword.size() - 3, 3, "OFF") != 0)
    return "the file does not start with an OFF header";
  // Binary and higher-dimensional variants are beyond this simple scan.
  if (keyword.find('n') != std::string::npos || keyword.find('4') != std::string::npos ||
      std::find(header.begin(), header.end(), "BINARY") != header.end())
    return "";
  bool homogeneous = keyword.find('H') != std::string::npos;

  std::size_t next = 1;
  std::vector<std::string> counts(header.begin() + 1, header.end());
  if (counts.empty()) {
    if (next >= lines.size()) return "the file ends after the header (truncated?)";
    counts = tokens_of(lines[next++].text);
  }
  // CGAL reads three counts even when the line has two, taking the third from the next line.
  if (counts.size() < 3)
    return "the header must give three counts (vertices, faces, edges), found " +
           std::to_string(counts.size());
  std::optional<long long> vertex_count = parse_integer(counts[0]);
  std::optional<long long> face_count =
      counts.size() >= 2 ? parse_integer(counts[1]) : std::optional<long long>();
  if (!vertex_count || !face_count || *vertex_count < 0 || *face_count < 0)
    return "the header does not give valid vertex and face counts";

  for (long long v = 0; v < *vertex_count; ++v, ++next) {
    if (next >= lines.size())
      return "the file ends after " + std::to_string(v) + " of " +
             std::to_string(*vertex_count) + " vertices (truncated?)";
    std::vector<std::string> tokens = tokens_of(lines[next].text);
    std::size_t needed = homogeneous ? 4 : 3;
    if (tokens.size() < needed)
      return "vertex " + std::to_string(v) + " (line " + std::to_string(lines[next].number) +
             ") has fewer than " + std::to_string(needed) + " coordinates";
    for (std::size_t c = 0; c < needed; ++c) {
      std::optional<double> value = parse_double(tokens[c]);
      if (!value)
        return "vertex " + std::to_string(v) + " (line " + std::to_string(lines[next].number) +
               ") has a coordinate that is not a number: '" + tokens[c] + "'";
      if (!std::isfinite(*value))
        return "vertex " + std::to_string(v) + " has a non-finite coordinate (" + tokens[c] + ")";
    }
  }
  if (*face_count == 0) return "the file contains no faces";
  for (long long f = 0; f < *face_count; ++f, ++next) {
    if (next >= lines.size())
      return "the file ends after " + std::to_string(f) + " of " + std::to_string(*face_count) +
             " faces (truncated?)";
    std::vector<std::string> tokens = tokens_of(lines[next].text);
    std::optional<long long> corners = parse_integer(tokens[0]);
    if (!corners || *corners < 1)
      return "face " + std::to_string(f) + " (line " + std::to_string(lines[next].number) +
             ") does not start with a valid corner count";
    if (static_cast<long long>(tokens.size()) - 1 < *corners)
      return "face " + std::to_string(f) + " (line " + std::to_string(lines[next].number) +
             ") lists " + std::to_string(*corners) + " corners but gives only " +
             std::to_string(tokens.size() - 1) + " indices";
    for (long long c = 1; c <= *corners; ++c) {
      std::optional<long long> index = parse_integer(tokens[c]);
      if (!index)
        return "face " + std::to_string(f) + " (line " + std::to_string(lines[next].number) +
               ") has an index that is not an integer: '" + tokens[c] + "'";
      if (*index < 0 || *index >= *vertex_count)
        return "face " + std::to_string(f) + " refers to vertex " + std::to_string(*index) +
               ", but there are only " + std::to_string(*vertex_count) + " vertices";
    }
  }
  return "";
}

// Returns what is wrong with an OBJ file, or an empty string if we cannot tell.
std::string diagnose_obj(const std::string& path) {
  long long vertex_count = 0;
  long long face_count = 0;
  for (const TextLine& line : content_lines(path)) {
    std::vector<std::string> tokens = tokens_of(line.text);
    if (tokens[0] == "v") {
      if (tokens.size() < 4)
        return "vertex " + std::to_string(vertex_count) + " (line " +
               std::to_string(line.number) + ") has fewer than 3 coordinates";
      for (std::size_t c = 1; c <= 3; ++c) {
        std::optional<double> value = parse_double(tokens[c]);
        if (!value)
          return "vertex " + std::to_string(vertex_count) + " (line " +
                 std::to_string(line.number) + ") has a coordinate that is not a number: '" +
                 tokens[c] + "'";
        if (!std::isfinite(*value))
          return "vertex " + std::to_string(vertex_count) + " has a non-finite coordinate (" +
                 tokens[c] + ")";
      }
      ++vertex_count;
    } else if (tokens[0] == "f") {
      for (std::size_t c = 1; c < tokens.size(); ++c) {
        std::string index_text = tokens[c].substr(0, tokens[c].find('/'));
        std::optional<long long> index = parse_integer(index_text);
        if (!index)
          return "face " + std::to_string(face_count) + " (line " + std::to_string(line.number) +
                 ") has an index that is not an integer: '" + tokens[c] + "'";
        // OBJ indices are 1-based; negative ones count back from the latest vertex.
        long long resolved = *index > 0 ? *index - 1 : vertex_count + *index;
        if (*index == 0 || resolved < 0 || resolved >= vertex_count)
          return "face " + std::to_string(face_count) + " (line " + std::to_string(line.number) +
                 ") refers to vertex " + index_text + ", but only " +
                 std::to_string(vertex_count) + " vertices precede it";
      }
      ++face_count;
    } else if (!std::isalpha(static_cast<unsigned char>(tokens[0][0]))) {
      return "line " + std::to_string(line.number) + " is not an OBJ statement";
    }
  }
  if (face_count == 0) return "the file contains no faces";
  return "";
}

// Newell's normal: robust for non-planar and non-convex polygons.
Kernel::Vector_3 newell_normal(const std::vector<Kernel::Point_3>& corners) {
  double nx = 0, ny = 0, nz = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Kernel::Point_3& a = corners[i];
    const Kernel::Point_3& b = corners[(i + 1) % corners.size()];
    nx += (a.y() - b.y()) * (a.z() + b.z());
    ny += (a.z() - b.z()) * (a.x() + b.x());
    nz += (a.x() - b.x()) * (a.y() + b.y());
  }
  return {nx, ny, nz};
}

// Triangulates a polygon with more than three corners, keeping its orientation. Convex
// polygons get a fan; others are ear-clipped in the plane of their dominant normal component.
// Returns false if no valid triangulation was found.
bool triangulate_polygon(const Polygon& polygon, const std::vector<Kernel::Point_3>& points,
                         std::vector<Triangle>& triangles) {
  const std::size_t k = polygon.size();
  Polygon sorted = polygon;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;

  std::vector<Kernel::Point_3> corners;
  for (std::size_t index : polygon) corners.push_back(points[index]);
  Kernel::Vector_3 normal = newell_normal(corners);
  double components[3] = {std::abs(normal.x()), std::abs(normal.y()), std::abs(normal.z())};
  int drop = static_cast<int>(std::max_element(components, components + 3) - components);
  if (components[drop] == 0) return false;
  const double sign[3] = {normal.x(), normal.y(), normal.z()};
  // Dropping coordinate `drop` keeps (drop+1, drop+2) as a right-handed pair, so the polygon is
  // counterclockwise in 2D exactly when the normal's dropped component is positive.
  const bool flip = sign[drop] < 0;
  std::vector<Kernel::Point_2> flat;
  for (const Kernel::Point_3& p : corners) {
    double u = p[(drop + 1) % 3], v = p[(drop + 2) % 3];
    flat.emplace_back(u, flip ? -v : v);
  }

  auto emit = [&](std::size_t a, std::size_t b, std::size_t c) {
    triangles.push_back({static_cast<std::int32_t>(polygon[a]),
                         static_cast<std::int32_t>(polygon[b]),
                         static_cast<std::int32_t>(polygon[c])});
  };

  bool convex = true;
  for (std::size_t i = 0; i < k && convex; ++i)
    convex = CGAL::orientation(flat[(i + k - 1) % k], flat[i], flat[(i + 1) % k]) ==
             CGAL::LEFT_TURN;
  if (convex) {
    for (std::size_t i = 1; i + 1 < k; ++i) emit(0, i, i + 1);
    return true;
  }

  auto is_ear = [&](std::size_t a, std::size_t b, std::size_t c,
                    const std::vector<std::size_t>& remaining) {
    if (CGAL::orientation(flat[a], flat[b], flat[c]) != CGAL::LEFT_TURN) return false;
    for (std::size_t other : remaining) {
      if (other == a || other == b || other == c) continue;
      // A corner on the ear's boundary blocks it too: clipping would create a T-junction.
      if (CGAL::orientation(flat[a], flat[b], flat[other]) != CGAL::RIGHT_TURN &&
          CGAL::orientation(flat[b], flat[c], flat[other]) != CGAL::RIGHT_TURN &&
          CGAL::orientation(flat[c], flat[a], flat[other]) != CGAL::RIGHT_TURN)
        return false;
    }
    return true;
  };
  std::vector<std::size_t> remaining(k);
  for (std::size_t i = 0; i < k; ++i) remaining[i] = i;
  // Walk around the polygon clipping ears; a full round without one means there is none.
  std::size_t i = 0, misses = 0;
  while (remaining.size() > 3) {
    const std::size_t n = remaining.size();
    if (misses >= n) return false;
    i %= n;
    std::size_t a = remaining[(i + n - 1) % n], b = remaining[i], c = remaining[(i + 1) % n];
    if (is_ear(a, b, c, remaining)) {
      emit(a, b, c);
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(i));
      misses = 0;
      if (i > 0) --i;  // the previous corner may have just become an ear
    } else {
      ++i;
      ++misses;
    }
  }
  if (CGAL::orientation(flat[remaining[0]], flat[remaining[1]], flat[remaining[2]]) !=
      CGAL::LEFT_TURN)
    return false;
  emit(remaining[0], remaining[1], remaining[2]);
  return true;
}

}  // namespace

// Counts an OFF or PLY header declares, checked against the file size before CGAL reads it:
// CGAL reserves memory for the declared counts, so a corrupt header asking for a billion
// vertices would otherwise exhaust memory instead of failing (found by fuzzing).
static void check_declared_counts(const std::string& path, const std::string& ext, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  std::string head(65536, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream lines(head);
  std::string line;
  long double vertices = 0, faces = 0;
  if (ext == "off") {
    std::vector<std::string> tokens;
    while (tokens.size() < 3 && std::getline(lines, line)) {
      const auto hash = line.find('#');
      for (const auto& t : tokens_of(hash == std::string::npos ? line : line.substr(0, hash))) tokens.push_back(t);
    }
    if (tokens.empty()) return;
    std::size_t first = 1;  // after the keyword (counts may follow it on the same line)
    if (tokens[0].find("OFF") == std::string::npos) first = 0;
    if (tokens.size() < first + 2) return;
    // CGAL reads a count from the leading digits of a token ("12+3" counts as 12): so do we.
    auto leading_integer = [](const std::string& token) -> std::optional<long long> {
      errno = 0;
      char* end = nullptr;
      const long long value = std::strtoll(token.c_str(), &end, 10);
      if (end == token.c_str()) return std::nullopt;
      if (errno == ERANGE) return std::numeric_limits<long long>::max();  // absurd: rejected below
      return value;
    };
    const auto v = leading_integer(tokens[first]), f = leading_integer(tokens[first + 1]);
    if (!v || !f) return;  // CGAL or the diagnosis reports a malformed header
    vertices = static_cast<long double>(*v);
    faces = static_cast<long double>(*f);
  } else if (ext == "ply") {
    // CGAL's PLY reader crashes on a "property" line before any "element" line (found by
    // fuzzing), so the header's structure is checked here first.
    bool in_element = false, ended = false;
    int line_number = 0;
    while (std::getline(lines, line)) {
      ++line_number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto tokens = tokens_of(line);
      if (line_number == 1) {
        if (line != "ply") throw InputError("cannot read '" + path + "': not a PLY file (no 'ply' line)");
        continue;
      }
      if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info" || tokens[0] == "format") continue;
      if (tokens[0] == "end_header") {
        ended = true;
        break;
      }
      if (tokens[0] == "element") {
        if (tokens.size() != 3 || !parse_integer(tokens[2]) || *parse_integer(tokens[2]) < 0)
          throw InputError("cannot read '" + path + "': malformed PLY header at line " + std::to_string(line_number) +
                           " (element NAME COUNT expected)");
        in_element = true;
      } else if (tokens[0] == "property") {
        if (!in_element)
          throw InputError("cannot read '" + path + "': malformed PLY header at line " + std::to_string(line_number) +
                           " (a property before any element)");
      } else {
        throw InputError("cannot read '" + path + "': malformed PLY header at line " + std::to_string(line_number) +
                         " (unknown keyword '" + tokens[0] + "')");
      }
    }
    if (!ended && head.size() < 65536)
      throw InputError("cannot read '" + path + "': the PLY header has no end_header line");
    lines.clear();
    lines.seekg(0);
    while (std::getline(lines, line) && line.rfind("end_header", 0) != 0) {
      const auto tokens = tokens_of(line);
      if (tokens.size() == 3 && tokens[0] == "element") {
        const auto n = parse_integer(tokens[2]);
        if (!n) continue;
        if (tokens[1] == "vertex") vertices = static_cast<long double>(*n);
        if (tokens[1] == "face") faces = static_cast<long double>(*n);
      }
    }
  } else {
    return;
  }
  // The smallest possible records: "0 0 0\n" per vertex and "3 0 1 2\n" per face (binary
  // variants are larger).
  // Small files are left to CGAL and the diagnosis, which says more precisely where they end.
  const long double smallest = vertices * 6 + faces * 8;
  if (smallest > static_cast<long double>(file_size) && smallest > 16.0L * 1024 * 1024)
    throw InputError("cannot read '" + path + "': the header declares " +
                     std::to_string(static_cast<long long>(vertices)) + " vertices and " +
                     std::to_string(static_cast<long long>(faces)) + " faces, more than a file of " +
                     std::to_string(file_size) + " bytes can hold (truncated or corrupt?)");
}

SurfaceMesh read_surface(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError("cannot open '" + path + "': no such file");
  if (fs::is_directory(status)) throw InputError("cannot open '" + path + "': is a directory");

  const std::string ext = lowercase_extension(path);
  if (ext != "off" && ext != "obj" && ext != "ply" && ext != "stl")
    throw InputError("cannot read '" + path + "': unknown format '" +
                     (ext.empty() ? std::string("(no extension)") : "." + ext) +
                     "' (supported: " + kSupportedFormats + ")");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe)
      throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  }

  check_declared_counts(path, ext, fs::file_size(path, ec));

  const std::string format = format_name(ext);
  const std::string prefix = "cannot read '" + path + "': ";
  std::vector<Kernel::Point_3> points;
  std::vector<Polygon> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons);
  } catch (const std::exception& e) {
    throw InputError(prefix + "not a valid " + format + " file (" + e.what() + ")");
  }
  if (!ok) {
    std::string problem;
    if (ext == "off") problem = diagnose_off(path);
    if (ext == "obj") problem = diagnose_obj(path);
    if (problem.empty())
      problem = "not a valid " + format + " file (truncated or malformed?)";
    throw InputError(prefix + problem);
  }

  if (polygons.empty()) {
    // CGAL's ASCII STL reader stops quietly at the first facet it cannot parse.
    const bool stl_with_content = ext == "stl" && fs::file_size(path, ec) > 0;
    throw InputError(prefix + "the file contains no faces" +
                     (stl_with_content ? " (truncated or malformed?)" : ""));
  }
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError(prefix + "too many vertices (" + std::to_string(points.size()) + ")");
  for (std::size_t v = 0; v < points.size(); ++v) {
    const Kernel::Point_3& p = points[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InputError(prefix + "vertex " + std::to_string(v) + " has a non-finite coordinate " +
                       coordinates_text(p));
  }

  SurfaceMesh surface;
  surface.points.reserve(points.size());
  for (const Kernel::Point_3& p : points) surface.points.push_back({p.x(), p.y(), p.z()});
  surface.triangles.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const Polygon& polygon = polygons[f];
    for (std::size_t index : polygon) {
      if (index < points.size()) continue;
      // CGAL's OBJ reader lets an index one past the end through, and has already turned
      // 1-based and negative indices into offsets; the file itself tells what was written.
      std::string problem = ext == "obj" ? diagnose_obj(path) : "";
      if (problem.empty())
        problem = "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) +
                  ", but there are only " + std::to_string(points.size()) + " vertices";
      throw InputError(prefix + problem);
    }
    if (polygon.size() < 3)
      throw InputError(prefix + "face " + std::to_string(f) + " has only " +
                       std::to_string(polygon.size()) + " corners");
    if (polygon.size() == 3) {
      surface.triangles.push_back({static_cast<std::int32_t>(polygon[0]),
                                   static_cast<std::int32_t>(polygon[1]),
                                   static_cast<std::int32_t>(polygon[2])});
    } else if (!triangulate_polygon(polygon, points, surface.triangles)) {
      throw InputError(prefix + "face " + std::to_string(f) + " has " +
                       std::to_string(polygon.size()) + " corners and cannot be triangulated");
    }
  }
  return surface;
}

}  // namespace partet
