#include "io/plain_off.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace partet {
namespace {

// The file mapped into memory, read only.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
      void* data = ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
      if (data != MAP_FAILED) {
        data_ = static_cast<const char*>(data);
        size_ = static_cast<std::size_t>(st.st_size);
        ::madvise(data, size_, MADV_SEQUENTIAL);
      }
    }
    ::close(fd);
  }
  ~MappedFile() {
    if (data_) ::munmap(const_cast<char*>(data_), size_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view text() const { return {data_, size_}; }
  bool ok() const { return data_ != nullptr; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

// Walks the text line by line; a line's tokens are read in order and must all be used.
class Scanner {
 public:
  explicit Scanner(std::string_view text) : p_(text.data()), end_(text.data() + text.size()) {}

  // Moves to the next line with content (skipping blank and comment lines); false at the end.
  bool next_line() {
    for (;;) {
      while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r' || *p_ == '\n')) ++p_;
      if (p_ == end_) return false;
      if (*p_ != '#') break;
      while (p_ < end_ && *p_ != '\n') ++p_;
    }
    line_end_ = p_;
    while (line_end_ < end_ && *line_end_ != '\n' && *line_end_ != '#') ++line_end_;
    return true;
  }
  bool word(std::string_view expected) {
    skip_blanks();
    if (static_cast<std::size_t>(line_end_ - p_) < expected.size() || std::string_view(p_, expected.size()) != expected)
      return false;
    p_ += expected.size();
    return p_ == line_end_ || is_blank(*p_);
  }
  template <class T>
  bool number(T& value) {
    skip_blanks();
    const auto [ptr, ec] = std::from_chars(p_, line_end_, value);
    if (ec != std::errc() || (ptr != line_end_ && !is_blank(*ptr))) return false;
    p_ = ptr;
    return true;
  }
  // Only blanks (or a comment) are left on the line; moves past it.
  bool line_done() {
    skip_blanks();
    if (p_ != line_end_) return false;
    while (p_ < end_ && *p_ != '\n') ++p_;
    return true;
  }

 private:
  static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
  void skip_blanks() {
    while (p_ < line_end_ && is_blank(*p_)) ++p_;
  }
  const char* p_;
  const char* end_;
  const char* line_end_ = nullptr;
};

bool read_counts(Scanner& in, std::int64_t& vertices, std::int64_t& faces) {
  std::int64_t edges = 0;
  if (!in.next_line() || !in.word("OFF") || !in.line_done() || !in.next_line()) return false;
  if (!in.number(vertices) || !in.number(faces) || !in.number(edges) || !in.line_done()) return false;
  return vertices >= 0 && faces > 0 && vertices <= INT32_MAX && faces <= INT32_MAX;
}

bool read_vertex(Scanner& in, Point3& p) {
  if (!in.next_line()) return false;
  for (double& x : p)
    if (!in.number(x) || !std::isfinite(x)) return false;
  return in.line_done();
}

bool read_triangle(Scanner& in, std::int64_t vertex_count, Triangle& t) {
  int corners = 0;
  if (!in.next_line() || !in.number(corners) || corners != 3) return false;
  for (auto& v : t)
    if (!in.number(v) || v < 0 || v >= vertex_count) return false;
  return in.line_done();
}

}  // namespace

std::optional<SurfaceMesh> read_plain_off(const std::string& path) {
  const MappedFile file(path);
  if (!file.ok()) return std::nullopt;
  Scanner in(file.text());
  std::int64_t vertex_count = 0, face_count = 0;
  if (!read_counts(in, vertex_count, face_count)) return std::nullopt;
  // A header declaring more than the file can hold is left to the general reader's guards.
  if (static_cast<std::uint64_t>(vertex_count) * 6 + static_cast<std::uint64_t>(face_count) * 8 > file.text().size())
    return std::nullopt;
  SurfaceMesh surface;
  surface.points.resize(static_cast<std::size_t>(vertex_count));
  for (Point3& p : surface.points)
    if (!read_vertex(in, p)) return std::nullopt;
  surface.triangles.resize(static_cast<std::size_t>(face_count));
  for (Triangle& t : surface.triangles)
    if (!read_triangle(in, vertex_count, t)) return std::nullopt;
  if (in.next_line()) return std::nullopt;  // trailing content
  return surface;
}

}  // namespace partet
