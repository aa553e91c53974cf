#include "io/surface_format.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <vector>

#include "partet/errors.hpp"

namespace partet {

const char* const kSupportedFormats = ".off, .obj, .ply, .stl";

namespace {

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
    if (++number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a byte order mark
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

// What is wrong with vertex v's line of an OFF file, or "".
std::string off_vertex_problem(const TextLine& line, long long v, bool homogeneous) {
  const std::vector<std::string> tokens = tokens_of(line.text);
  const std::size_t needed = homogeneous ? 4 : 3;
  const std::string where = "vertex " + std::to_string(v) + " (line " + std::to_string(line.number) + ")";
  if (tokens.size() < needed) return where + " has fewer than " + std::to_string(needed) + " coordinates";
  for (std::size_t c = 0; c < needed; ++c) {
    std::optional<double> value = parse_double(tokens[c]);
    if (!value) return where + " has a coordinate that is not a number: '" + tokens[c] + "'";
    if (!std::isfinite(*value))
      return "vertex " + std::to_string(v) + " has a non-finite coordinate (" + tokens[c] + ")";
  }
  return "";
}

// What is wrong with face f's line of an OFF file, or "".
std::string off_face_problem(const TextLine& line, long long f, long long vertex_count) {
  const std::vector<std::string> tokens = tokens_of(line.text);
  const std::string where = "face " + std::to_string(f) + " (line " + std::to_string(line.number) + ")";
  std::optional<long long> corners = parse_integer(tokens[0]);
  if (!corners || *corners < 1) return where + " does not start with a valid corner count";
  if (static_cast<long long>(tokens.size()) - 1 < *corners)
    return where + " lists " + std::to_string(*corners) + " corners but gives only " +
           std::to_string(tokens.size() - 1) + " indices";
  for (long long c = 1; c <= *corners; ++c) {
    std::optional<long long> index = parse_integer(tokens[c]);
    if (!index) return where + " has an index that is not an integer: '" + tokens[c] + "'";
    if (*index < 0 || *index >= vertex_count)
      return "face " + std::to_string(f) + " refers to vertex " + std::to_string(*index) + ", but there are only " +
             std::to_string(vertex_count) + " vertices";
  }
  return "";
}

}  // namespace

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
    return "the header must give three counts (vertices, faces, edges), found " + std::to_string(counts.size());
  std::optional<long long> vertex_count = parse_integer(counts[0]);
  std::optional<long long> face_count = counts.size() >= 2 ? parse_integer(counts[1]) : std::optional<long long>();
  if (!vertex_count || !face_count || *vertex_count < 0 || *face_count < 0)
    return "the header does not give valid vertex and face counts";

  for (long long v = 0; v < *vertex_count; ++v, ++next) {
    if (next >= lines.size())
      return "the file ends after " + std::to_string(v) + " of " + std::to_string(*vertex_count) +
             " vertices (truncated?)";
    if (std::string problem = off_vertex_problem(lines[next], v, homogeneous); !problem.empty()) return problem;
  }
  if (*face_count == 0) return "the file contains no faces";
  for (long long f = 0; f < *face_count; ++f, ++next) {
    if (next >= lines.size())
      return "the file ends after " + std::to_string(f) + " of " + std::to_string(*face_count) + " faces (truncated?)";
    if (std::string problem = off_face_problem(lines[next], f, *vertex_count); !problem.empty()) return problem;
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
        return "vertex " + std::to_string(vertex_count) + " (line " + std::to_string(line.number) +
               ") has fewer than 3 coordinates";
      for (std::size_t c = 1; c <= 3; ++c) {
        std::optional<double> value = parse_double(tokens[c]);
        if (!value)
          return "vertex " + std::to_string(vertex_count) + " (line " + std::to_string(line.number) +
                 ") has a coordinate that is not a number: '" + tokens[c] + "'";
        if (!std::isfinite(*value))
          return "vertex " + std::to_string(vertex_count) + " has a non-finite coordinate (" + tokens[c] + ")";
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
                 ") refers to vertex " + index_text + ", but only " + std::to_string(vertex_count) +
                 " vertices precede it";
      }
      ++face_count;
    } else if (!std::isalpha(static_cast<unsigned char>(tokens[0][0]))) {
      return "line " + std::to_string(line.number) + " is not an OBJ statement";
    }
  }
  if (face_count == 0) return "the file contains no faces";
  return "";
}

// Counts an OFF or PLY header declares, checked against the file size before CGAL reads it:
// CGAL reserves memory for the declared counts, so a corrupt header asking for a billion
// vertices would otherwise exhaust memory instead of failing (found by fuzzing).
namespace {

struct DeclaredCounts {
  long double vertices = 0, faces = 0;
};

// CGAL reads a count from the leading digits of a token ("12+3" counts as 12): so do we.
std::optional<long long> leading_integer(const std::string& token) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(token.c_str(), &end, 10);
  if (end == token.c_str()) return std::nullopt;
  if (errno == ERANGE) return std::numeric_limits<long long>::max();  // absurd: rejected by the caller
  return value;
}

// The counts in an OFF header (none when it is malformed: CGAL or the diagnosis reports that).
DeclaredCounts off_counts(std::istringstream& lines) {
  std::string line;
  std::vector<std::string> tokens;
  while (tokens.size() < 3 && std::getline(lines, line)) {
    const auto hash = line.find('#');
    for (const auto& t : tokens_of(hash == std::string::npos ? line : line.substr(0, hash))) tokens.push_back(t);
  }
  if (tokens.empty()) return {};
  const std::size_t first = tokens[0].find("OFF") == std::string::npos ? 0 : 1;  // counts may follow the keyword
  if (tokens.size() < first + 2) return {};
  const auto v = leading_integer(tokens[first]), f = leading_integer(tokens[first + 1]);
  if (!v || !f) return {};
  return {static_cast<long double>(*v), static_cast<long double>(*f)};
}

// CGAL's PLY reader crashes on a "property" line before any "element" line (found by fuzzing),
// so the header's structure is checked first.
void check_ply_header(std::istringstream& lines, const std::string& path, bool complete) {
  const std::string prefix = "cannot read '" + path + "': ";
  bool in_element = false;
  int line_number = 0;
  std::string line;
  while (std::getline(lines, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto tokens = tokens_of(line);
    const std::string at = prefix + "malformed PLY header at line " + std::to_string(line_number);
    if (line_number == 1) {
      if (line != "ply") throw InputError(prefix + "not a PLY file (no 'ply' line)");
      continue;
    }
    if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info" || tokens[0] == "format") continue;
    if (tokens[0] == "end_header") return;
    if (tokens[0] == "element") {
      if (tokens.size() != 3 || !parse_integer(tokens[2]) || *parse_integer(tokens[2]) < 0)
        throw InputError(at + " (element NAME COUNT expected)");
      in_element = true;
    } else if (tokens[0] == "property") {
      if (!in_element) throw InputError(at + " (a property before any element)");
    } else {
      throw InputError(at + " (unknown keyword '" + tokens[0] + "')");
    }
  }
  if (complete) throw InputError(prefix + "the PLY header has no end_header line");
}

DeclaredCounts ply_counts(std::istringstream& lines) {
  DeclaredCounts counts;
  std::string line;
  while (std::getline(lines, line) && line.rfind("end_header", 0) != 0) {
    const auto tokens = tokens_of(line);
    if (tokens.size() != 3 || tokens[0] != "element") continue;
    const auto n = parse_integer(tokens[2]);
    if (!n) continue;
    if (tokens[1] == "vertex") counts.vertices = static_cast<long double>(*n);
    if (tokens[1] == "face") counts.faces = static_cast<long double>(*n);
  }
  return counts;
}

// An STL file is binary (an 80-byte header, a facet count n, then exactly 50 bytes per facet) or
// ASCII ("solid ..."). Anything else (random data, a byte-order mark before "solid") would make
// CGAL read nonsense for a long time or report the wrong problem.
void check_stl(const std::string& head, const std::string& path, std::uintmax_t file_size) {
  const std::string prefix = "cannot read '" + path + "': ";
  bool binary_size_matches = false;
  if (head.size() >= 84) {
    std::uint32_t facets = 0;
    std::memcpy(&facets, head.data() + 80, sizeof facets);
    binary_size_matches = file_size == 84 + 50 * static_cast<std::uintmax_t>(facets);
  }
  const std::size_t first = head.find_first_not_of(" \t\r\n");
  const bool ascii = first != std::string::npos && head.compare(first, 5, "solid") == 0;
  if (!ascii && !binary_size_matches)
    throw InputError(prefix + "not an STL file: it does not start with 'solid', and its size (" +
                     std::to_string(file_size) + " bytes) is not that of a binary STL with the facet count it declares");
}

}  // namespace

void check_declared_counts(const std::string& path, const std::string& ext, std::uintmax_t file_size) {
  constexpr std::size_t kHead = 65536;
  std::ifstream in(path, std::ios::binary);
  std::string head(kHead, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.rfind("\xEF\xBB\xBF", 0) == 0) head.erase(0, 3);  // a UTF-8 byte order mark: read past it
  std::istringstream lines(head);
  DeclaredCounts counts;
  if (ext == "off") {
    counts = off_counts(lines);
  } else if (ext == "ply") {
    check_ply_header(lines, path, head.size() < kHead);
    lines.clear();
    lines.seekg(0);
    counts = ply_counts(lines);
  } else {
    if (ext == "stl") check_stl(head, path, file_size);
    return;
  }
  // The smallest possible records: "0 0 0\n" per vertex and "3 0 1 2\n" per face (binary
  // variants are larger). Small files are left to CGAL and the diagnosis, which says more
  // precisely where they end.
  const long double smallest = counts.vertices * 6 + counts.faces * 8;
  if (smallest > static_cast<long double>(file_size) && smallest > 16.0L * 1024 * 1024)
    throw InputError("cannot read '" + path + "': the header declares " +
                     std::to_string(static_cast<long long>(counts.vertices)) + " vertices and " +
                     std::to_string(static_cast<long long>(counts.faces)) + " faces, more than a file of " +
                     std::to_string(file_size) + " bytes can hold (truncated or corrupt?)");
}

}  // namespace partet
