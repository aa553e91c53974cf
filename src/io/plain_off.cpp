#include "io/plain_off.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "common/parallel.hpp"

namespace partet {
namespace {

// The file read in blocks: memory stays small, and a file rewritten while it is read gives an
// error (a memory-mapped one would kill the process with SIGBUS).
class BlockText {
 public:
  explicit BlockText(int fd) : fd_(fd), buffer_(std::size_t{8} << 20) {}

  // The next line (without its '\n'); false at the end. Valid until the next call.
  bool next(std::string_view& line) {
    for (;;) {
      const char* start = buffer_.data() + begin_;
      if (const void* nl = std::memchr(start, '\n', end_ - begin_)) {
        const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
        line = std::string_view(start, length);
        begin_ += length + 1;
        return true;
      }
      if (eof_) {
        if (begin_ == end_) return false;
        line = std::string_view(start, end_ - begin_);  // a last line without '\n'
        begin_ = end_;
        return true;
      }
      refill();
    }
  }
  // The complete lines after those taken so far (the last line without '\n' once the file has
  // ended), at least `wanted` bytes of them unless the file ends first; false at the end. Valid
  // until the next call.
  bool next_lines(std::string_view& lines, std::size_t wanted) {
    while (!eof_ && end_ - begin_ < wanted) refill();
    const char* start = buffer_.data() + begin_;
    std::size_t length = end_ - begin_;
    if (!eof_) {
      while (length > 0 && start[length - 1] != '\n') --length;
      if (length == 0) {  // one line longer than what is buffered: read on
        refill();
        return next_lines(lines, wanted);
      }
    }
    if (length == 0) return false;
    lines = std::string_view(start, length);
    begin_ += length;
    return true;
  }
  bool failed() const { return failed_; }

 private:
  void refill() {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);  // more than the buffer holds
    for (;;) {
      const ssize_t n = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) failed_ = true;
      if (n <= 0) {
        eof_ = true;
        return;
      }
      end_ += static_cast<std::size_t>(n);
      return;
    }
  }

  int fd_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false, failed_ = false;
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// A number at p (after blanks) ending at a blank, a comment or the line's end; p moves past it.
template <class T>
bool parse_number(const char*& p, const char* end, T& value) {
  while (p < end && is_blank(*p)) ++p;
  const auto [ptr, ec] = std::from_chars(p, end, value);
  if (ec != std::errc() || (ptr != end && !is_blank(*ptr) && *ptr != '#')) return false;
  p = ptr;
  return true;
}

// Only blanks, then perhaps a comment, are left on the line.
bool at_line_end(const char*& p, const char* end) {
  while (p < end && is_blank(*p)) ++p;
  return p == end || *p == '#';
}

// Walks the text line by line; a line's tokens are read in order and must all be used.
class Scanner {
 public:
  explicit Scanner(BlockText& text) : text_(text) {}

  // Moves to the next line with content (skipping blank and comment lines); false at the end.
  bool next_line() {
    std::string_view line;
    while (text_.next(line)) {
      if (first_) {
        first_ = false;
        if (line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // a UTF-8 byte order mark
      }
      if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      p_ = line.data();
      line_end_ = line.data() + line.size();
      skip_blanks();
      if (p_ != line_end_) return true;
    }
    return false;
  }
  bool word(std::string_view expected) {
    skip_blanks();
    if (static_cast<std::size_t>(line_end_ - p_) < expected.size() || std::string_view(p_, expected.size()) != expected)
      return false;
    p_ += expected.size();
    return p_ == line_end_ || is_blank(*p_);
  }
  // (The line has lost its comment already.)
  template <class T>
  bool number(T& value) {
    return parse_number(p_, line_end_, value);
  }
  bool line_done() { return at_line_end(p_, line_end_); }

 private:
  void skip_blanks() {
    while (p_ < line_end_ && is_blank(*p_)) ++p_;
  }
  BlockText& text_;
  bool first_ = true;
  const char* p_ = nullptr;
  const char* line_end_ = nullptr;
};

bool read_counts(Scanner& in, std::int64_t& vertices, std::int64_t& faces) {
  std::int64_t edges = 0;
  if (!in.next_line() || !in.word("OFF") || !in.line_done() || !in.next_line()) return false;
  if (!in.number(vertices) || !in.number(faces) || !in.number(edges) || !in.line_done()) return false;
  return vertices >= 0 && faces > 0 && vertices <= INT32_MAX && faces <= INT32_MAX;
}

// The vertices and triangles of a run of whole lines, in order. A content line is a vertex
// (three numbers) until the first triangle ("3 i j k"), and a triangle after it, so runs can be
// read apart and joined after; `ok` is false on anything else.
struct ParsedLines {
  std::vector<Point3> points;
  std::vector<Triangle> triangles;
  bool ok = true;

  void parse(std::string_view text, std::int64_t vertex_count) {
    points.clear(), triangles.clear(), ok = true;  // keeps the capacity for the next block
    const char* p = text.data();
    const char* const end = p + text.size();
    while (p < end && ok) {
      const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
      if (!eol) eol = end;
      parse_line(p, eol, vertex_count);
      p = eol + 1;
    }
  }

 private:
  // Tried as a vertex while no triangle has come, then as a triangle: one pass over nearly
  // every line.
  void parse_line(const char* p, const char* end, std::int64_t vertex_count) {
    if (at_line_end(p, end)) return;  // blank or comment
    Point3 point;
    if (triangles.empty() && vertex(p, end, point)) return points.push_back(point);
    Triangle t;
    if (triangle(p, end, vertex_count, t)) return triangles.push_back(t);
    ok = false;
  }

  static bool vertex(const char* p, const char* end, Point3& point) {
    for (double& x : point)
      if (!parse_number(p, end, x) || !std::isfinite(x)) return false;
    return at_line_end(p, end);
  }

  static bool triangle(const char* p, const char* end, std::int64_t vertex_count, Triangle& t) {
    int corners = 0;
    if (!parse_number(p, end, corners) || corners != 3) return false;
    for (auto& v : t)
      if (!parse_number(p, end, v) || v < 0 || v >= vertex_count) return false;
    return at_line_end(p, end);
  }
};

// Reads the lines after the header in blocks, each cut into runs at line ends that threads parse
// side by side (parsing numbers is most of the reading time), then appends the runs in order.
bool read_body(BlockText& text, std::int64_t vertex_count, SurfaceMesh& surface) {
  constexpr std::size_t kBlockBytes = std::size_t{32} << 20;
  const unsigned threads = usable_cpus();
  std::vector<ParsedLines> runs(threads);
  std::string_view block;
  while (text.next_lines(block, kBlockBytes)) {
    std::vector<std::string_view> parts;
    for (unsigned t = 0; t < threads && !block.empty(); ++t) {
      std::size_t cut = t + 1 == threads ? block.size() : std::max<std::size_t>(1, block.size() / (threads - t));
      while (cut < block.size() && block[cut - 1] != '\n') ++cut;
      parts.push_back(block.substr(0, cut));
      block.remove_prefix(cut);
    }
    parallel_for(parts.size(), threads, [&](std::size_t i) { runs[i].parse(parts[i], vertex_count); });
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const ParsedLines& run = runs[i];
      if (!run.ok || (!run.points.empty() && !surface.triangles.empty())) return false;
      if (surface.points.size() + run.points.size() > static_cast<std::size_t>(vertex_count)) return false;
      surface.points.insert(surface.points.end(), run.points.begin(), run.points.end());
      surface.triangles.insert(surface.triangles.end(), run.triangles.begin(), run.triangles.end());
    }
  }
  return true;
}

}  // namespace

std::optional<SurfaceMesh> read_plain_off(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::nullopt;
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) return std::nullopt;
  const auto file_size = static_cast<std::uint64_t>(st.st_size);
  BlockText text(fd);
  Scanner in(text);
  std::int64_t vertex_count = 0, face_count = 0;
  if (!read_counts(in, vertex_count, face_count)) return std::nullopt;
  // A header declaring more than the file can hold is left to the general reader's guards.
  if (static_cast<std::uint64_t>(vertex_count) * 6 + static_cast<std::uint64_t>(face_count) * 8 > file_size)
    return std::nullopt;
  SurfaceMesh surface;
  surface.points.reserve(static_cast<std::size_t>(vertex_count));
  surface.triangles.reserve(static_cast<std::size_t>(face_count));
  if (!read_body(text, vertex_count, surface) || text.failed()) return std::nullopt;  // or a read error
  // Each count exactly: no vertex and no triangle missing, no trailing content.
  if (surface.points.size() != static_cast<std::size_t>(vertex_count) ||
      surface.triangles.size() != static_cast<std::size_t>(face_count))
    return std::nullopt;
  return surface;
}

}  // namespace partet
