#include "io/vtu_read.hpp"

#include <zlib.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "io/file_text.hpp"
#include "io/mesh_formats.hpp"
#include "io/xml_text.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

constexpr std::size_t kNone = std::string_view::npos;

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw InputError("'" + path + "' " + what); }

// The value of attribute `name` in an XML tag's text ("" when it has none).
std::string attribute(std::string_view tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const std::size_t at = tag.find(key);
  if (at == kNone) return "";
  const std::size_t begin = at + key.size(), end = tag.find('"', begin);
  return end == kNone ? "" : std::string(tag.substr(begin, end - begin));
}

// The tags of an element in XML text, each from its '<' to its '>'.
std::vector<std::string_view> tags_named(std::string_view text, const std::string& element) {
  std::vector<std::string_view> tags;
  const std::string open = "<" + element + " ";
  for (std::size_t at = text.find(open); at != kNone; at = text.find(open, at + 1)) {
    const std::size_t end = text.find('>', at);
    if (end == kNone) break;
    tags.push_back(text.substr(at, end - at + 1));
  }
  return tags;
}

std::uint64_t number_of(const std::string& text, const std::string& path, const std::string& what) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) fail(path, "has no valid " + what);
  return value;
}

// One .vtu file as partet writes it: the XML head, then the appended arrays, each a UInt64 header
// [blocks, block size, last block's size, each block's compressed size] and zlib blocks.
class VtuFile {
 public:
  explicit VtuFile(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw InputError("cannot open '" + path + "'");
    read_head();
    const std::vector<std::string_view> pieces = tags_named(head_, "Piece");
    if (pieces.size() != 1) fail(path_, "has " + std::to_string(pieces.size()) + " pieces, not one");
    points_ = number_of(attribute(pieces[0], "NumberOfPoints"), path_, "NumberOfPoints");
    cells_ = number_of(attribute(pieces[0], "NumberOfCells"), path_, "NumberOfCells");
  }

  std::uint64_t points() const { return points_; }
  std::uint64_t cells() const { return cells_; }
  bool has(const std::string& name) const { return !array_tag(name).empty(); }

  // The array `name`: `count` values of VTK type `type` (T's) with `components` each.
  template <class T>
  std::vector<T> array(const std::string& name, const std::string& type, int components, std::uint64_t count) {
    const std::string_view tag = array_tag(name);
    if (tag.empty()) fail(path_, "has no " + name + " array");
    if (attribute(tag, "type") != type || attribute(tag, "format") != "appended" ||
        attribute(tag, "NumberOfComponents") != std::to_string(components))
      fail(path_, "has its " + name + " array in another form than partet writes (" + type + ", " +
                      std::to_string(components) + " components, appended)");
    if (count > (std::uint64_t(1) << 40) / sizeof(T) / static_cast<std::uint64_t>(components))
      fail(path_, "has too many values in its " + name + " array");
    std::vector<T> values(count * static_cast<std::uint64_t>(components));
    read_compressed(base_ + number_of(attribute(tag, "offset"), path_, name + " offset"), values.data(),
                    values.size() * sizeof(T), name);
    return values;
  }

 private:
  // The text before the appended data ('_' after <AppendedData encoding="raw">); base_ is where
  // the data begins.
  void read_head() {
    const std::string marker = "<AppendedData encoding=\"raw\">";
    std::string text;
    std::size_t found = kNone, underscore = kNone;
    char chunk[1 << 16];
    while (text.size() < (std::size_t(1) << 20)) {
      in_.read(chunk, sizeof chunk);
      text.append(chunk, static_cast<std::size_t>(in_.gcount()));
      if (found == kNone) found = text.find(marker);
      if (found != kNone) underscore = text.find('_', found + marker.size());
      if (underscore != kNone || in_.gcount() == 0) break;
    }
    in_.clear();
    if (underscore == kNone) fail(path_, "is not a .vtu file with raw appended data, as partet writes it");
    head_ = text.substr(0, found);
    base_ = underscore + 1;
    const std::vector<std::string_view> file = tags_named(head_, "VTKFile");
    if (file.empty() || attribute(file[0], "type") != "UnstructuredGrid" ||
        attribute(file[0], "byte_order") != "LittleEndian" || attribute(file[0], "header_type") != "UInt64" ||
        attribute(file[0], "compressor") != "vtkZLibDataCompressor")
      fail(path_, "is not a compressed little-endian UnstructuredGrid with UInt64 headers, as partet writes it");
  }

  std::string_view array_tag(const std::string& name) const {
    for (std::string_view tag : tags_named(head_, "DataArray"))
      if (attribute(tag, "Name") == name) return tag;
    return {};
  }

  void read_at(std::uint64_t at, void* into, std::size_t bytes, const std::string& name) {
    in_.seekg(static_cast<std::streamoff>(at));
    if (!in_.read(static_cast<char*>(into), static_cast<std::streamsize>(bytes)))
      fail(path_, "ends early (in its " + name + " array)");
  }

  void read_compressed(std::uint64_t at, void* into, std::size_t bytes, const std::string& name) {
    std::uint64_t header[3];
    read_at(at, header, sizeof header, name);
    const std::uint64_t blocks = header[0], block = header[1], last = header[2];
    const bool fits = blocks == 0 ? bytes == 0
                                  : block > 0 && last > 0 && last <= block && blocks <= bytes / block + 1 &&
                                        (blocks - 1) * block + last == bytes;
    if (!fits) fail(path_, "has a " + name + " array of another size than its cell counts say");
    std::vector<std::uint64_t> sizes(blocks);
    read_at(at + sizeof header, sizes.data(), sizes.size() * sizeof(std::uint64_t), name);
    std::uint64_t next = at + sizeof header + sizes.size() * sizeof(std::uint64_t);
    std::vector<unsigned char> packed;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::uint64_t length = b + 1 < blocks ? block : last;
      if (sizes[b] > compressBound(static_cast<uLong>(length)) + 64)
        fail(path_, "has a damaged " + name + " array (a block larger than zlib makes it)");
      packed.resize(sizes[b]);
      read_at(next, packed.data(), packed.size(), name);
      next += sizes[b];
      uLongf out = static_cast<uLongf>(length);
      if (uncompress(static_cast<unsigned char*>(into) + b * block, &out, packed.data(),
                     static_cast<uLong>(packed.size())) != Z_OK ||
          out != length)
        fail(path_, "has a damaged " + name + " array (it does not decompress)");
    }
  }

  std::string path_;
  std::ifstream in_;
  std::string head_;
  std::uint64_t base_ = 0, points_ = 0, cells_ = 0;
};

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

}  // namespace

std::vector<std::string> pvtu_files(const std::string& path) {
  std::error_code no_size;  // a missing file: file_text says so
  if (std::filesystem::file_size(path, no_size) > (std::uintmax_t(1) << 26) && !no_size)
    fail(path, "is too large for a .pvtu index");
  const std::string text = file_text(path);
  const std::vector<std::string_view> file = tags_named(text, "VTKFile");
  if (file.empty() || attribute(file[0], "type") != "PUnstructuredGrid")
    fail(path, "is not a .pvtu index (a PUnstructuredGrid)");
  std::vector<std::string> files{path};
  for (std::string_view piece : tags_named(text, "Piece")) {
    const std::string source = xml_unescaped(attribute(piece, "Source"));
    if (source.empty()) fail(path, "has a piece without a Source");
    files.push_back(source[0] == '/' ? source : directory_of(path) + source);
  }
  if (files.size() == 1) fail(path, "names no piece files");
  return files;
}

void read_vtu_file(const std::string& path, MeshSink& sink, bool in_set) {
  VtuFile file(path);
  const std::uint64_t points = file.points(), cells = file.cells();
  std::vector<std::int64_t> ids;  // each point's id in the whole mesh (a piece file's); else its index
  {
    if (file.has(kGlobalPointIds))
      ids = file.array<std::int64_t>(kGlobalPointIds, "Int64", 1, points);
    else if (in_set)
      fail(path, std::string("has no ") + kGlobalPointIds +
                     " point data, which numbers a piece file's points in the whole mesh (partet writes it since "
                     "November 2026: mesh again to check the set)");
    const std::vector<double> xyz = file.array<double>("Points", "Float64", 3, points);
    for (std::uint64_t i = 0; i < points; ++i) {
      const MeshId id = ids.empty() ? static_cast<MeshId>(i) : ids[i];
      if (id < 0) fail(path, "gives point " + std::to_string(i) + " the negative id " + std::to_string(id));
      sink.node(id, {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
    }
  }
  {
    const std::vector<std::int64_t> offsets = file.array<std::int64_t>("offsets", "Int64", 1, cells);
    const std::vector<std::uint8_t> types = file.array<std::uint8_t>("types", "UInt8", 1, cells);
    for (std::uint64_t c = 0; c < cells; ++c)
      if (types[c] != 10 || offsets[c] != static_cast<std::int64_t>(4 * (c + 1)))
        fail(path, "has cell " + std::to_string(c) + ", which is not a tet (partet writes only tets)");
  }
  const std::vector<std::int64_t> connectivity = file.array<std::int64_t>("connectivity", "Int64", 1, 4 * cells);
  for (std::uint64_t c = 0; c < cells; ++c) {
    std::array<MeshId, 4> tet;
    for (int k = 0; k < 4; ++k) {
      const std::int64_t v = connectivity[4 * c + static_cast<std::uint64_t>(k)];
      if (v < 0 || static_cast<std::uint64_t>(v) >= points)
        fail(path, "has a tet with point " + std::to_string(v) + " of " + std::to_string(points));
      tet[static_cast<std::size_t>(k)] = ids.empty() ? v : ids[static_cast<std::size_t>(v)];
    }
    sink.tet(tet);
  }
}

}  // namespace partet
