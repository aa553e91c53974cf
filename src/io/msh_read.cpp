#include "io/msh_read.hpp"

#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <vector>

#include "io/file_text.hpp"
#include "io/mesh_formats.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

// One MSH file's bytes and a cursor over its numbers: text separated by white space, or binary
// (size_t 8 bytes, int 4 bytes, double 8 bytes, this machine's byte order as partet writes it).
class MshCursor {
 public:
  explicit MshCursor(const std::string& path) : path_(path), text_(file_text(path)) {
    const std::string head = "$MeshFormat\n";
    if (text_.compare(0, head.size(), head) != 0) fail("does not start with $MeshFormat");
    at_ = head.size();
    if (word() != "4.1") fail("is not MSH version 4.1");
    binary_ = integer_word() == 1;
    if (integer_word() != 8) fail("does not use 8-byte sizes");
    if (binary_) {
      skip_line();
      at_ += sizeof(int);  // the byte-order marker
    }
  }

  // Moves to just after the line "$NAME"; false (cursor unchanged) when there is none.
  bool section(const std::string& name) {
    const std::string line = "\n$" + name + "\n";
    const std::size_t found = text_.find(line, at_ == 0 ? 0 : at_ - 1);
    if (found == std::string::npos) return false;
    at_ = found + line.size();
    return true;
  }
  void expect_section(const std::string& name) {
    if (!section(name)) fail("has no $" + name + " section");
  }

  std::uint64_t size() {
    if (!binary_) return static_cast<std::uint64_t>(integer_word());
    return raw<std::uint64_t>();
  }
  std::int64_t tag() {
    if (!binary_) return integer_word();
    return raw<std::int32_t>();
  }
  double real() {
    if (!binary_) {
      const std::string_view w = word();
      double v = 0;
      if (std::from_chars(w.data(), w.data() + w.size(), v).ec != std::errc()) fail("has a malformed number");
      return v;
    }
    return raw<double>();
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError("'" + path_ + "' " + what); }

 private:
  template <class T>
  T raw() {
    if (at_ + sizeof(T) > text_.size()) fail("ends early");
    T v;
    std::memcpy(&v, text_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::string_view word() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    const std::size_t begin = at_;
    while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    if (begin == at_) fail("ends early");
    return std::string_view(text_).substr(begin, at_ - begin);
  }
  std::int64_t integer_word() {
    const std::string_view w = word();
    std::int64_t v = 0;
    if (std::from_chars(w.data(), w.data() + w.size(), v).ec != std::errc()) fail("has a malformed number");
    return v;
  }
  void skip_line() {
    while (at_ < text_.size() && text_[at_] != '\n') ++at_;
    ++at_;
  }

  std::string path_, text_;
  std::size_t at_ = 0;
  bool binary_ = false;
};

// A node's id: its tag - 1.
MeshId node_id(std::uint64_t tag, const MshCursor& in) {
  if (tag < 1 || tag > static_cast<std::uint64_t>(INT64_MAX)) in.fail("has node tag " + std::to_string(tag));
  return static_cast<std::int64_t>(tag - 1);
}

// $Nodes and $Elements open alike: the number of blocks, then the number of entries and their
// lowest and highest tags (not needed here). Returns the number of blocks; each block then opens
// with its entity's dimension and tag, and a third int (parametric, or element type).
std::uint64_t open_section(MshCursor& in, const char* name) {
  in.expect_section(name);
  const std::uint64_t blocks = in.size();
  in.size(), in.size(), in.size();
  return blocks;
}

// Calls node(tag, point) for every node of the file, in its order.
template <class OnNode>
void read_nodes(MshCursor& in, const OnNode& node) {
  for (std::uint64_t b = 0, blocks = open_section(in, "Nodes"); b < blocks; ++b) {
    in.tag(), in.tag();
    if (in.tag() != 0) in.fail("has parametric nodes");
    const std::uint64_t count = in.size();
    std::vector<std::uint64_t> tags(count);
    for (auto& tag : tags) tag = in.size();
    for (std::uint64_t tag : tags) node(tag, Point3{in.real(), in.real(), in.real()});
  }
}

// Calls triangle(tags) and tet(tags) for every element of the file (node tags, as given).
template <class OnTriangle, class OnTet>
void read_elements(MshCursor& in, const OnTriangle& triangle, const OnTet& tet) {
  for (std::uint64_t b = 0, blocks = open_section(in, "Elements"); b < blocks; ++b) {
    in.tag(), in.tag();
    const std::int64_t type = in.tag();
    const std::uint64_t count = in.size();
    if (type != 2 && type != 4) in.fail("has elements of type " + std::to_string(type) + " (not triangles or tets)");
    for (std::uint64_t e = 0; e < count; ++e) {
      in.size();  // the element's tag
      if (type == 2) {
        std::array<std::uint64_t, 3> tags;
        for (auto& tag : tags) tag = in.size();
        triangle(tags);
      } else {
        std::array<std::uint64_t, 4> tags;
        for (auto& tag : tags) tag = in.size();
        tet(tags);
      }
    }
  }
}

template <std::size_t N>
std::array<MeshId, N> ids_of(const std::array<std::uint64_t, N>& tags, const MshCursor& in) {
  std::array<MeshId, N> ids;
  for (std::size_t k = 0; k < N; ++k) ids[k] = node_id(tags[k], in);
  return ids;
}

// The other files of the set PATH belongs to (none for a single file), by PATH's own content,
// which `in` holds: PREFIX_1.msh ... PREFIX_N.msh but PATH.
std::vector<std::string> other_set_files(MshCursor& in, const std::string& path) {
  if (!in.section("PartitionedEntities")) return {};
  const std::uint64_t partitions = in.size();
  std::string prefix;
  if (!partition_file_prefix(path, prefix)) in.fail("is a partition file but not named PREFIX_i.msh");
  std::vector<std::string> files;
  for (std::uint64_t i = 1; i <= partitions; ++i)
    if (partition_file(prefix, i) != path) files.push_back(partition_file(prefix, i));
  return files;
}

void read_cells(MshCursor& in, MeshSink& sink) {
  read_nodes(in, [&](std::uint64_t tag, const Point3& p) { sink.node(node_id(tag, in), p); });
  read_elements(
      in, [&](const auto& tags) { sink.triangle(ids_of(tags, in), 1); },
      [&](const auto& tags) { sink.tet(ids_of(tags, in)); });
}

}  // namespace

std::vector<std::string> read_msh_named(const std::string& path, MeshSink& sink) {
  MshCursor in(path);
  std::vector<std::string> files = other_set_files(in, path);
  files.insert(files.begin(), path);
  read_cells(in, sink);
  return files;
}

void read_msh_file(const std::string& path, MeshSink& sink) {
  MshCursor in(path);
  read_cells(in, sink);
}

}  // namespace partet
