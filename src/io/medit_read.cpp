#include "io/medit_read.hpp"

#include <cctype>
#include <charconv>
#include <string_view>

#include "io/file_text.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

// The file's words, one after another (MEDIT's ASCII form is keywords and numbers separated by
// white space; '#' starts a comment line).
class MeditWords {
 public:
  explicit MeditWords(const std::string& path) : path_(path), text_(file_text(path)) {}

  bool done() {
    skip_space();
    return at_ >= text_.size();
  }
  std::string_view word() {
    if (done()) fail("ends early");
    const std::size_t begin = at_;
    while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    return std::string_view(text_).substr(begin, at_ - begin);
  }
  template <class T>
  T number() {
    const std::string_view w = word();
    T value{};
    const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), value);
    if (error != std::errc() || end != w.data() + w.size()) fail("has a malformed number '" + std::string(w) + "'");
    return value;
  }
  // A vertex index (from 1) as a point id (from 0).
  MeshId vertex() {
    const std::int64_t index = number<std::int64_t>();
    if (index < 1) fail("has vertex index " + std::to_string(index));
    return index - 1;
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError("'" + path_ + "' " + what); }

 private:
  void skip_space() {
    for (;;) {
      while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
      if (at_ >= text_.size() || text_[at_] != '#') return;
      while (at_ < text_.size() && text_[at_] != '\n') ++at_;
    }
  }

  std::string path_, text_;
  std::size_t at_ = 0;
};

}  // namespace

void read_medit_file(const std::string& path, MeshSink& sink) {
  MeditWords in(path);
  if (in.done() || in.word() != "MeshVersionFormatted") in.fail("does not start with MeshVersionFormatted");
  in.number<int>();
  while (!in.done()) {
    const std::string_view keyword = in.word();
    if (keyword == "End") return;
    if (keyword == "Dimension") {
      if (in.number<int>() != 3) in.fail("is not three-dimensional");
      continue;
    }
    if (keyword != "Vertices" && keyword != "Triangles" && keyword != "Tetrahedra")
      in.fail("has a section '" + std::string(keyword) + "', which partet does not write");
    const auto count = in.number<std::uint64_t>();
    for (std::uint64_t i = 0; i < count; ++i) {
      if (keyword == "Vertices") {
        const Point3 p{in.number<double>(), in.number<double>(), in.number<double>()};
        in.number<std::int64_t>();  // reference
        sink.node(static_cast<MeshId>(i), p);
      } else if (keyword == "Triangles") {
        const std::array<MeshId, 3> ids{in.vertex(), in.vertex(), in.vertex()};
        sink.triangle(ids, in.number<int>());
      } else {
        const std::array<MeshId, 4> ids{in.vertex(), in.vertex(), in.vertex(), in.vertex()};
        in.number<std::int64_t>();  // reference: the region
        sink.tet(ids);
      }
    }
  }
}

}  // namespace partet
