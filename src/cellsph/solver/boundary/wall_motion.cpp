#include "cellsph/solver/boundary/wall_motion.hpp"

#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"

namespace cellsph {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  for (;;) {
    const auto comma = line.find(',');
    cells.push_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return cells;
    line.remove_prefix(comma + 1);
  }
}

// At most 40 characters of a cell, printable, for a message.
std::string shown(std::string_view v) {
  std::string s;
  for (const char c : v.substr(0, 40)) s += (c >= 32 && c < 127) ? c : '?';
  if (v.size() > 40) s += "...";
  return "\"" + s + "\"";
}

}  // namespace

void parse_motion_table(std::string_view text, const std::string& file, int dim,
                        std::vector<MotionTableRow>& out) {
  auto fail = [&](std::size_t line, const std::string& what) {
    throw InputError(file + " line " + std::to_string(line) + ": " + what);
  };
  const std::vector<std::string> with_angle = dim == 2
                                                  ? std::vector<std::string>{"time", "x", "y", "angle"}
                                                  : std::vector<std::string>{"time", "x", "y", "z", "angle"};
  std::vector<std::string> columns;
  std::size_t line_no = 0, rows = 0;
  double last_t = 0;
  while (!text.empty()) {
    const auto nl = text.find('\n');
    const std::string_view raw = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    ++line_no;
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    const auto cells = split(line);
    if (columns.empty()) {
      // The header: the columns without the angle, or with it.
      const std::size_t n = cells.size();
      const bool ok_count = n == with_angle.size() - 1 || n == with_angle.size();
      for (std::size_t c = 0; c < n && ok_count; ++c) {
        const std::string want = c + 1 == with_angle.size() ? "angle" : with_angle[c];
        if (cells[c] != want)
          fail(line_no, "column " + std::to_string(c + 1) + ": header " + shown(cells[c]) + ", expected \"" +
                            want + "\" (" + std::to_string(dim) + "D columns: time,x,y" +
                            (dim == 3 ? ",z" : "") + "[,angle])");
      }
      if (!ok_count)
        fail(line_no, "header has " + std::to_string(n) + " columns, expected time,x,y" +
                          (dim == 3 ? ",z" : "") + " with an optional angle (" + std::to_string(dim) + "D)");
      columns.assign(cells.begin(), cells.end());
      continue;
    }
    if (cells.size() != columns.size())
      fail(line_no, "has " + std::to_string(cells.size()) + " values, the header names " +
                        std::to_string(columns.size()) + " columns");
    double v[5] = {0, 0, 0, 0, 0};
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string_view cell = cells[c];
      double x = 0;
      const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), x);
      const std::string where = "column " + std::to_string(c + 1) + " (" + columns[c] + "): ";
      if (cell.empty() || r.ec != std::errc() || r.ptr != cell.data() + cell.size())
        fail(line_no, where + shown(cell) + " is not a number");
      if (!std::isfinite(x) || std::abs(x) > 1e12)
        fail(line_no, where + shown(cell) + " is not a finite number of at most 1e12");
      v[c] = x;
    }
    if (rows > 0 && !(v[0] > last_t))
      fail(line_no, "column 1 (time): " + shown(cells[0]) + " does not increase (the row before has " +
                        std::to_string(last_t) + ")");
    MotionTableRow row;
    row.t = v[0];
    for (int a = 0; a < dim; ++a) row.d[a] = v[1 + a];
    if (columns.size() == with_angle.size()) row.angle_deg = v[columns.size() - 1];
    out.push_back(row);
    last_t = v[0];
    ++rows;
  }
  if (columns.empty())
    throw InputError(file + ": empty, expected a header time,x,y" + std::string(dim == 3 ? ",z" : "") +
                     "[,angle] and rows");
  if (rows == 0) throw InputError(file + ": has a header but no rows");
}

}  // namespace cellsph
