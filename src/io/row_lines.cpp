#include "io/row_lines.hpp"

#include <algorithm>
#include <cstring>

#include "io/buffered_file.hpp"
#include "io/msh_numbers.hpp"
#include "io/tetgen_files.hpp"
#include "io/text_sink.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

template <class Row>
Row row_at(const RowsToFormat& rows, std::size_t i) {
  Row row;
  std::memcpy(&row, static_cast<const char*>(rows.data) + i * sizeof(Row), sizeof(Row));
  return row;
}

// A tet row in the mesh's ids.
GlobalTet tet_at(const RowsToFormat& rows, std::size_t i) { return rows.ids(row_at<Tet>(rows, i)); }

template <class Sink>
void medit_lines(Sink& out, RowLines lines, const RowsToFormat& rows) {
  for (std::size_t i = 0; i < rows.count; ++i) {
    if (lines == RowLines::medit_vertex) {
      for (double c : row_at<Point3>(rows, i)) out.real(c), out.space();
      out.text("0\n");
      continue;
    }
    for (std::int64_t v : tet_at(rows, i)) out.integer(v + 1), out.space();
    out.integer(rows.region[i]);
    out.newline();
  }
}

template <class Sink>
void msh_lines(Sink& sink, bool binary, bool points, const RowsToFormat& rows) {
  MshNumbers<Sink> out(sink, binary);
  for (std::size_t i = 0; i < rows.count; ++i) {
    if (points) {
      for (double c : row_at<Point3>(rows, i)) out.real(c);
    } else {
      out.size(static_cast<std::uint64_t>(rows.number_from + rows.first) + i);
      for (std::int64_t v : tet_at(rows, i)) out.size(static_cast<std::uint64_t>(v) + 1);
    }
    out.end_line();
  }
}

// VTK's raw arrays, as they lie in memory.
template <class Sink>
void vtu_values(Sink& out, RowLines lines, const RowsToFormat& rows) {
  for (std::size_t i = 0; i < rows.count; ++i) {
    if (lines == RowLines::vtu_points) {
      const Point3 point = row_at<Point3>(rows, i);
      out.bytes(point.data(), sizeof point);
    } else if (lines == RowLines::vtu_connectivity) {
      const GlobalTet ids = tet_at(rows, i);
      out.bytes(ids.data(), sizeof ids);
    } else {
      out.bytes((lines == RowLines::vtu_piece ? rows.piece : rows.region) + i, sizeof(std::int32_t));
    }
  }
}

// TetGen's .ele lines of tets whose ids are not all as they are, and its .neigh lines (64-bit
// rows), as tetgen_files.hpp formats them.
template <class Sink>
void wide_tetgen_lines(Sink& out, RowLines lines, const RowsToFormat& rows) {
  for (std::size_t i = 0; i < rows.count; ++i) {
    out.integer(rows.first + static_cast<std::int64_t>(i));
    const GlobalTet row = lines == RowLines::tetgen_ele ? tet_at(rows, i) : row_at<GlobalTet>(rows, i);
    for (std::int64_t n : row) out.space(), out.integer(n);
    out.newline();
  }
}

template <class Sink>
void format_rows(Sink& out, RowLines lines, const RowsToFormat& rows) {
  switch (lines) {
    case RowLines::tetgen_ele:
    case RowLines::tetgen_neigh:
      return wide_tetgen_lines(out, lines, rows);
    case RowLines::vtu_points:
    case RowLines::vtu_connectivity:
    case RowLines::vtu_piece:
    case RowLines::vtu_region:
      return vtu_values(out, lines, rows);
    case RowLines::medit_vertex:
    case RowLines::medit_tet:
      return medit_lines(out, lines, rows);
    case RowLines::msh_node:
      return msh_lines(out, false, true, rows);
    case RowLines::msh_tet:
      return msh_lines(out, false, false, rows);
    case RowLines::msh_node_binary:
      return msh_lines(out, true, true, rows);
    case RowLines::msh_tet_binary:
      return msh_lines(out, true, false, rows);
    default:
      throw InternalError("no such rows to format");
  }
}

TetgenFile tetgen_file(RowLines lines) {
  return lines == RowLines::tetgen_node ? TetgenFile::node : TetgenFile::ele;
}

// The rows TetGen's own formatter writes (the .neigh rows are wider than its int32 ones, as are
// the ids of tets not all in the mesh's ids).
bool is_tetgen(RowLines lines, const RowsToFormat& rows) {
  return lines == RowLines::tetgen_node || (lines == RowLines::tetgen_ele && rows.ids.as_is());
}

}  // namespace

bool formats_points(RowLines lines) {
  return lines == RowLines::tetgen_node || lines == RowLines::medit_vertex || lines == RowLines::msh_node ||
         lines == RowLines::msh_node_binary || lines == RowLines::vtu_points;
}

std::size_t row_bytes(RowLines lines) {
  return formats_points(lines) ? sizeof(Point3) : lines == RowLines::tetgen_neigh ? 4 * sizeof(std::int64_t) : sizeof(Tet);
}

void append_row_lines(std::string& text, RowLines lines, const RowsToFormat& rows) {
  const auto* data = static_cast<const char*>(rows.data);
  const auto first = static_cast<std::size_t>(rows.first);
  if (is_tetgen(lines, rows)) return append_tetgen_lines(text, tetgen_file(lines), data, first, rows.count, SIZE_MAX);
  text.reserve(text.size() + rows.count * (formats_points(lines) ? 64 : 48));  // about a line's length
  TextSink sink(text);
  format_rows(sink, lines, rows);
  sink.flush();
}

void write_row_lines(BufferedFile& out, RowLines lines, const RowsToFormat& rows) {
  const auto* data = static_cast<const char*>(rows.data);
  const auto first = static_cast<std::size_t>(rows.first);
  if (is_tetgen(lines, rows)) return write_tetgen_lines(out, tetgen_file(lines), data, first, rows.count);
  format_rows(out, lines, rows);
}

void write_row_lines(ByteSink& out, RowLines lines, const RowsToFormat& rows) {
  constexpr std::size_t kRows = std::size_t{1} << 16;
  std::string text;
  for (std::size_t from = 0; from < rows.count; from += kRows) {
    RowsToFormat part = rows;
    part.count = std::min(kRows, rows.count - from);
    part.first += static_cast<std::int64_t>(from);
    part.data = static_cast<const char*>(rows.data) + from * row_bytes(lines);
    if (rows.region) part.region = rows.region + from;
    if (rows.piece) part.piece = rows.piece + from;
    text.clear();
    append_row_lines(text, lines, part);
    out.bytes(text.data(), text.size());
  }
}

}  // namespace partet
