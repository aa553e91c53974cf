// TetGen .node/.ele/.face/.neigh writing and reading.
#include "partet/tetgen_files.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/buffered_file.hpp"
#include "partet/errors.hpp"
#include "topology.hpp"

namespace partet {
namespace {

// ---------------------------------------------------------------------------------------------
// Writing

void write_node(const std::vector<Point3>& points, const std::string& path) {
  BufferedFile out(path);
  out.integer(static_cast<std::int64_t>(points.size()));
  out.text(" 3 0 0\n");
  for (std::size_t i = 0; i < points.size(); ++i) {
    out.integer(static_cast<std::int64_t>(i));
    for (double x : points[i]) {
      out.space();
      out.real(x);
    }
    out.newline();
  }
  out.close();
}

// .ele and .neigh share a layout: index and four integers.
void write_quads(const std::vector<Tet>& rows, const char* header_tail, const std::string& path) {
  BufferedFile out(path);
  out.integer(static_cast<std::int64_t>(rows.size()));
  out.text(header_tail);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    out.integer(static_cast<std::int64_t>(i));
    for (std::int32_t v : rows[i]) {
      out.space();
      out.integer(v);
    }
    out.newline();
  }
  out.close();
}

void write_face(const std::vector<Triangle>& faces, const std::string& path) {
  BufferedFile out(path);
  out.integer(static_cast<std::int64_t>(faces.size()));
  out.text(" 1\n");
  for (std::size_t i = 0; i < faces.size(); ++i) {
    out.integer(static_cast<std::int64_t>(i));
    for (std::int32_t v : faces[i]) {
      out.space();
      out.integer(v);
    }
    out.text(" 1\n");
  }
  out.close();
}

// ---------------------------------------------------------------------------------------------
// Reading

// A whole file in memory, handed out one meaningful line at a time (comments and blank lines
// skipped), with typed token parsing that reports file and line on malformed content.
class LineReader {
 public:
  explicit LineReader(std::string path) : path_(std::move(path)) {
    std::FILE* f = std::fopen(path_.c_str(), "rb");
    if (!f) throw InputError("cannot open " + path_ + ": " + std::strerror(errno));
    // Size first, one read: growing the string chunk by chunk copies 100 MB files many times.
    bool failed = std::fseek(f, 0, SEEK_END) != 0;
    long size = failed ? -1 : std::ftell(f);
    failed = failed || size < 0 || std::fseek(f, 0, SEEK_SET) != 0;
    if (!failed) {
      text_.resize(static_cast<std::size_t>(size));
      failed = std::fread(text_.data(), 1, text_.size(), f) != text_.size();
    }
    std::fclose(f);
    if (failed) throw InputError("cannot read " + path_);
  }

  // Moves to the next line holding data; false at end of file.
  bool next_line() {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string::npos) end = text_.size();
      std::string_view line(text_.data() + pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      if (std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      line_ = line;
      skip_space();
      if (!line_.empty()) return true;
    }
    return false;
  }

  // Like next_line(), but running out of lines is an error.
  void expect_line(const char* what) {
    if (!next_line()) throw InputError(path_ + ": unexpected end of file, expected " + what);
  }

  bool has_token() const { return !line_.empty(); }

  std::int64_t integer(const char* what) {
    std::int64_t value = 0;
    auto [ptr, ec] = std::from_chars(line_.data(), line_.data() + line_.size(), value);
    consume(ptr, ec == std::errc(), what);
    return value;
  }

  std::int64_t integer_or(std::int64_t fallback, const char* what) { return has_token() ? integer(what) : fallback; }

  double real(const char* what) {
    double value = 0;
    // from_chars rejects an explicit '+', which printf-style writers may emit.
    if (line_.size() > 1 && line_[0] == '+' && line_[1] != '-') line_.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(line_.data(), line_.data() + line_.size(), value);
    consume(ptr, ec == std::errc(), what);
    if (!std::isfinite(value)) error(std::string("non-finite ") + what);
    return value;
  }

  [[noreturn]] void error(const std::string& message) const {
    throw InputError(path_ + " line " + std::to_string(line_number_) + ": " + message);
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
  void skip_space() {
    std::size_t i = 0;
    while (i < line_.size() && is_space(line_[i])) ++i;
    line_.remove_prefix(i);
  }
  // A token must be followed by white space or the end of the line: "12abc" is malformed.
  void consume(const char* ptr, bool parsed, const char* what) {
    std::size_t length = static_cast<std::size_t>(ptr - line_.data());
    if (!parsed || length == 0 || (length < line_.size() && !is_space(line_[length]))) {
      std::string_view token = line_.substr(0, line_.find_first_of(" \t\r\v\f"));
      if (token.empty()) error(std::string("missing ") + what);
      error(std::string("expected ") + what + ", found '" + std::string(token) + "'");
    }
    line_.remove_prefix(length);
    skip_space();
  }

  std::string path_;
  std::string text_;
  std::size_t pos_ = 0;
  long line_number_ = 0;
  std::string_view line_;
};

// The count on a header line, checked to be usable as a vector size.
std::int64_t read_count(LineReader& in, const char* what) {
  std::int64_t count = in.integer(what);
  if (count < 0 || count > INT32_MAX) in.error(std::string("invalid ") + what + " " + std::to_string(count));
  return count;
}

// Reads a row's leading index: the first row fixes the numbering base (0 or 1, as TetGen
// does), and later rows must follow it consecutively.
std::int64_t read_row_index(LineReader& in, std::int64_t row, std::int64_t& base) {
  std::int64_t index = in.integer("index");
  if (row == 0) {
    if (index != 0 && index != 1) in.error("first index must be 0 or 1, found " + std::to_string(index));
    base = index;
  } else if (index != base + row) {
    in.error("expected index " + std::to_string(base + row) + ", found " + std::to_string(index));
  }
  return index;
}

std::int32_t read_vertex_ref(LineReader& in, std::int64_t base, std::size_t vertex_count) {
  std::int64_t v = in.integer("vertex index") - base;
  if (v < 0 || v >= static_cast<std::int64_t>(vertex_count))
    in.error("vertex index " + std::to_string(v + base) + " out of range");
  return static_cast<std::int32_t>(v);
}

std::vector<Point3> read_node(const std::string& path, std::int64_t& base) {
  LineReader in(path);
  in.expect_line("the header");
  std::int64_t count = read_count(in, "number of points");
  if (std::int64_t dim = in.integer_or(3, "dimension"); dim != 3)
    in.error("dimension must be 3, found " + std::to_string(dim));
  std::vector<Point3> points(static_cast<std::size_t>(count));
  base = 0;
  for (std::int64_t i = 0; i < count; ++i) {
    in.expect_line("a point");
    read_row_index(in, i, base);
    for (double& x : points[i]) x = in.real("coordinate");
    // Attributes and boundary markers follow; they carry nothing we use.
  }
  return points;
}

std::vector<Tet> read_ele(const std::string& path, std::int64_t vertex_base, std::size_t vertex_count) {
  LineReader in(path);
  in.expect_line("the header");
  std::int64_t count = read_count(in, "number of tetrahedra");
  if (std::int64_t corners = in.integer_or(4, "nodes per tetrahedron"); corners != 4 && corners != 10)
    in.error("nodes per tetrahedron must be 4 or 10, found " + std::to_string(corners));
  std::vector<Tet> tets(static_cast<std::size_t>(count));
  std::int64_t row_base = 0;
  for (std::int64_t i = 0; i < count; ++i) {
    in.expect_line("a tetrahedron");
    read_row_index(in, i, row_base);
    // Second-order nodes and region attributes may follow the corners; ignored.
    for (std::int32_t& v : tets[i]) v = read_vertex_ref(in, vertex_base, vertex_count);
  }
  return tets;
}

std::vector<Triangle> read_face(const std::string& path, std::int64_t vertex_base, std::size_t vertex_count) {
  LineReader in(path);
  in.expect_line("the header");
  std::int64_t count = read_count(in, "number of faces");
  std::vector<Triangle> faces(static_cast<std::size_t>(count));
  std::int64_t row_base = 0;
  for (std::int64_t i = 0; i < count; ++i) {
    in.expect_line("a face");
    read_row_index(in, i, row_base);
    for (std::int32_t& v : faces[i]) v = read_vertex_ref(in, vertex_base, vertex_count);
  }
  return faces;
}

bool file_exists(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  std::fclose(f);
  return true;
}

}  // namespace

void write_tetgen_files(const TetMesh& mesh, const std::vector<Triangle>& boundary_faces, const std::string& prefix) {
  const std::string names[4] = {prefix + ".node", prefix + ".ele", prefix + ".face", prefix + ".neigh"};
  auto tmp = [](const std::string& name) { return name + ".tmp"; };
  auto remove_temporaries = [&] {
    for (const std::string& name : names) std::remove(tmp(name).c_str());
  };
  // TetMesh may come without neighbours (e.g. straight from a merge); write -1 rather than
  // an inconsistent file.
  const std::vector<Tet>* neighbours = &mesh.neighbours;
  std::vector<Tet> no_neighbours;
  if (mesh.neighbours.size() != mesh.tets.size()) {
    no_neighbours.assign(mesh.tets.size(), Tet{-1, -1, -1, -1});
    neighbours = &no_neighbours;
  }
  try {
    write_node(mesh.points, tmp(names[0]));
    write_quads(mesh.tets, " 4 0\n", tmp(names[1]));
    write_face(boundary_faces, tmp(names[2]));
    write_quads(*neighbours, " 4\n", tmp(names[3]));
  } catch (...) {
    remove_temporaries();
    throw;
  }
  // Rename only once everything is on disk, so a failed run never leaves a mixed set.
  for (const std::string& name : names) {
    if (std::rename(tmp(name).c_str(), name.c_str()) != 0) {
      std::string reason = std::strerror(errno);
      remove_temporaries();
      throw OutputError("cannot rename " + tmp(name) + " to " + name + ": " + reason);
    }
  }
}

TetMesh read_tetgen_files(const std::string& prefix, std::vector<Triangle>* boundary_faces) {
  TetMesh mesh;
  std::int64_t vertex_base = 0;
  mesh.points = read_node(prefix + ".node", vertex_base);
  mesh.tets = read_ele(prefix + ".ele", vertex_base, mesh.points.size());
  mesh.neighbours = compute_neighbours(mesh.tets, mesh.points.size(), CrowdedFace::leave_open);
  if (boundary_faces) {
    boundary_faces->clear();
    std::string face_path = prefix + ".face";
    if (file_exists(face_path)) *boundary_faces = read_face(face_path, vertex_base, mesh.points.size());
  }
  return mesh;
}

}  // namespace partet
