#include "cellsph/io/points_csv.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "cellsph/core/error.hpp"

namespace cellsph {

namespace {

constexpr std::string_view kSpaces = " \t\r";

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(kSpaces);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(kSpaces);
  return s.substr(b, e - b + 1);
}

// A value as shown in an error message: quoted, cut short, control characters made visible.
std::string shown(std::string_view v) {
  constexpr std::size_t kMax = 40;
  std::string s = "'";
  for (std::size_t i = 0; i < v.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(v[i]);
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    } else {
      s += static_cast<char>(c);
    }
  }
  s += v.size() > kMax ? "...'" : "'";
  return s;
}

std::string where(std::string_view source, std::size_t line) {
  return "points file '" + std::string(source) + "', line " + std::to_string(line);
}

struct Column {
  std::string_view name;
  std::size_t index = 0;  // 0-based position in the header
  std::vector<double>* target = nullptr;
  bool positive = false;  // h must be > 0
};

// Strict number: the whole (trimmed) field, finite. std::from_chars does not accept a leading '+',
// which spreadsheets sometimes write; we allow it when a digit or '.' follows.
double parse_field(std::string_view raw, const Column& col, std::string_view source, std::size_t line) {
  const std::string_view v = trim(raw);
  auto fail = [&](const char* what) {
    throw InputError(where(source, line) + ", column '" + std::string(col.name) + "' (column " +
                     std::to_string(col.index + 1) + "): " + what + ": " + shown(raw));
  };
  if (v.empty()) fail("empty value");
  const char* first = v.data();
  const char* last = v.data() + v.size();
  if (*first == '+' && v.size() > 1 &&
      (std::isdigit(static_cast<unsigned char>(first[1])) || first[1] == '.'))
    ++first;
  double value = 0;
  const auto [ptr, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ec == std::errc::result_out_of_range) fail("number out of range for double");
  if (ec != std::errc() || ptr != last) fail("not a number");
  if (!std::isfinite(value)) fail("not a finite number");
  if (col.positive && !(value > 0)) fail("support length h must be > 0");
  return value;
}

// The lines of a text, each without its '\n' or "\r\n", numbered from 1.
struct Lines {
  std::string_view text;
  std::size_t pos = 0;
  std::size_t line_no = 0;

  bool next(std::string_view& line) {
    if (pos >= text.size()) return false;
    const auto nl = text.find('\n', pos);
    const auto end = nl == std::string_view::npos ? text.size() : nl;
    line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    ++line_no;
    return true;
  }
  // The text after the lines read so far.
  [[nodiscard]] std::string_view rest() const {
    return pos < text.size() ? text.substr(pos) : std::string_view{};
  }
};

// The header's fields, trimmed.
std::vector<std::string_view> column_names(std::string_view header) {
  std::vector<std::string_view> names;
  for (std::size_t b = 0;;) {
    const auto c = header.find(',', b);
    names.push_back(trim(header.substr(b, c == std::string_view::npos ? std::string_view::npos : c - b)));
    if (c == std::string_view::npos) break;
    b = c + 1;
  }
  return names;
}

// The position of column `name` in the header, or -1; a name that appears twice is an error.
std::ptrdiff_t find_column(const std::vector<std::string_view>& names, std::string_view name,
                           std::string_view source) {
  std::ptrdiff_t found = -1;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k] != name) continue;
    if (found >= 0)
      throw InputError(where(source, 1) + ": column '" + std::string(name) + "' appears twice (columns " +
                       std::to_string(found + 1) + " and " + std::to_string(k + 1) + ")");
    found = static_cast<std::ptrdiff_t>(k);
  }
  return found;
}

// The columns the table is read from: x and y, then z and h where the header has them, each filling its
// vector of `t`. Sets t.dim.
std::vector<Column> table_columns(const std::vector<std::string_view>& names, std::string_view header,
                                  PointsTable& t, std::string_view source) {
  const std::ptrdiff_t ix = find_column(names, "x", source), iy = find_column(names, "y", source),
                       iz = find_column(names, "z", source), ih = find_column(names, "h", source);
  for (auto [idx, name] : {std::pair{ix, "x"}, std::pair{iy, "y"}})
    if (idx < 0)
      throw InputError(where(source, 1) + ": missing column '" + name + "' (header: " + shown(header) +
                       "; expected x,y or x,y,z, optionally h)");
  t.dim = iz >= 0 ? 3 : 2;
  std::vector<Column> cols;
  cols.push_back({"x", static_cast<std::size_t>(ix), &t.coord[0], false});
  cols.push_back({"y", static_cast<std::size_t>(iy), &t.coord[1], false});
  if (iz >= 0) cols.push_back({"z", static_cast<std::size_t>(iz), &t.coord[2], false});
  if (ih >= 0) cols.push_back({"h", static_cast<std::size_t>(ih), &t.h, true});
  return cols;
}

// The rows after the header, each of n_fields fields, the columns' fields parsed into their vectors. Blank
// lines may only end the file.
void read_rows(Lines& lines, const std::vector<Column>& cols, std::size_t n_fields, std::string_view source) {
  // column position -> needed column (or none), so each row is split in one pass.
  std::vector<const Column*> by_position(n_fields, nullptr);
  for (const auto& c : cols) by_position[c.index] = &c;

  // Reserve from a cheap line count so 10^6 rows do not reallocate.
  const std::string_view rest = lines.rest();
  const auto approx_rows = static_cast<std::size_t>(std::count(rest.begin(), rest.end(), '\n')) + 1;
  for (const auto& c : cols) c.target->reserve(approx_rows);

  std::size_t blank_line = 0;  // first blank line seen; only allowed at the end of the file
  std::string_view line;
  while (lines.next(line)) {
    if (trim(line).empty()) {
      if (blank_line == 0) blank_line = lines.line_no;
      continue;
    }
    if (blank_line != 0)
      throw InputError(where(source, blank_line) +
                       ": empty row (every row after the header must hold a point)");
    std::size_t field = 0;
    for (std::size_t b = 0;; ++field) {
      const auto c = line.find(',', b);
      const auto e = c == std::string_view::npos ? line.size() : c;
      if (field < n_fields && by_position[field] != nullptr) {
        const Column& col = *by_position[field];
        col.target->push_back(parse_field(line.substr(b, e - b), col, source, lines.line_no));
      }
      if (c == std::string_view::npos) break;
      b = c + 1;
    }
    if (field + 1 != n_fields)
      throw InputError(where(source, lines.line_no) + ": row has " + std::to_string(field + 1) +
                       " field(s), the header has " + std::to_string(n_fields) + ": " + shown(line));
  }
}
}  // namespace

PointsTable parse_points_csv(std::string_view text, std::string_view source) {
  // A UTF-8 byte-order mark is not part of the first column's name.
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw InputError("points file '" + std::string(source) +
                     "' is empty (expected a header row naming columns x,y or x,y,z)");

  Lines lines{text};
  // Header: leading blank lines are not allowed to hide it.
  std::string_view header;
  lines.next(header);
  if (trim(header).empty())
    throw InputError(where(source, lines.line_no) +
                     ": expected the header row (x,y or x,y,z), found an empty line");

  PointsTable t;
  const std::vector<std::string_view> names = column_names(header);
  const std::vector<Column> cols = table_columns(names, header, t, source);
  read_rows(lines, cols, names.size(), source);
  if (t.size() == 0)
    throw InputError("points file '" + std::string(source) + "' has a header but no data rows");
  // Indices are 32-bit in the neighbour lists.
  if (t.size() >= std::numeric_limits<std::uint32_t>::max())
    throw InputError("points file '" + std::string(source) + "' has " + std::to_string(t.size()) +
                     " rows; at most 4294967294 particles are supported");
  return t;
}

PointsTable read_points_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(name.c_str(), "rb"), &std::fclose);
  if (!f) throw InputError("cannot read points file '" + name + "': " + std::strerror(errno));
  std::string text;
  std::error_code size_ec;
  if (const auto size = std::filesystem::file_size(file, size_ec); !size_ec) text.reserve(size);
  char buf[1 << 16];
  while (true) {
    const std::size_t got = std::fread(buf, 1, sizeof buf, f.get());
    text.append(buf, got);
    if (got < sizeof buf) {
      if (std::ferror(f.get()))
        throw InputError("cannot read points file '" + name + "': " + std::strerror(errno));
      break;
    }
  }
  return parse_points_csv(text, name);
}

}  // namespace cellsph
