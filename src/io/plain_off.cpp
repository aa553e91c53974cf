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
  std::size_t bytes_read() const { return total_; }
  bool failed() const { return failed_; }

 private:
  void refill() {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);  // a line longer than the buffer
    for (;;) {
      const ssize_t n = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) failed_ = true;
      if (n <= 0) {
        eof_ = true;
        return;
      }
      end_ += static_cast<std::size_t>(n);
      total_ += static_cast<std::size_t>(n);
      return;
    }
  }

  int fd_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0, total_ = 0;
  bool eof_ = false, failed_ = false;
};

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
  template <class T>
  bool number(T& value) {
    skip_blanks();
    const auto [ptr, ec] = std::from_chars(p_, line_end_, value);
    if (ec != std::errc() || (ptr != line_end_ && !is_blank(*ptr))) return false;
    p_ = ptr;
    return true;
  }
  // Only blanks are left on the line.
  bool line_done() {
    skip_blanks();
    return p_ == line_end_;
  }

 private:
  static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
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
  surface.points.resize(static_cast<std::size_t>(vertex_count));
  for (Point3& p : surface.points)
    if (!read_vertex(in, p)) return std::nullopt;
  surface.triangles.resize(static_cast<std::size_t>(face_count));
  for (Triangle& t : surface.triangles)
    if (!read_triangle(in, vertex_count, t)) return std::nullopt;
  if (in.next_line() || text.failed()) return std::nullopt;  // trailing content, or a read error
  return surface;
}

}  // namespace partet
