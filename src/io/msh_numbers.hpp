// Gmsh MSH 4.1's numbers (internal header): one writer for the MSH files' heads and elements
// (io/msh.cpp) and for the rows a rank formats for rank 0 (io/row_lines.cpp), so both give the
// same bytes.
#pragma once
#include <cstdint>

namespace partet {

// Into a sink (BufferedFile, TextSink): as text, each number followed by a space and each line
// by a newline; in binary, size_t (8 bytes), int (4 bytes) and double as they lie in memory, no
// newlines.
template <class Sink>
class MshNumbers {
 public:
  MshNumbers(Sink& out, bool binary) : out_(out), binary_(binary) {}
  void size(std::uint64_t v) {
    binary_ ? out_.bytes(&v, sizeof v) : (out_.integer(static_cast<std::int64_t>(v)), out_.space());
  }
  void tag(std::int32_t v) { binary_ ? out_.bytes(&v, sizeof v) : (out_.integer(v), out_.space()); }
  void real(double v) { binary_ ? out_.bytes(&v, sizeof v) : (out_.real(v), out_.space()); }
  void end_line() {
    if (!binary_) out_.newline();
  }
  bool binary() const { return binary_; }

 private:
  Sink& out_;
  bool binary_;
};

}  // namespace partet
