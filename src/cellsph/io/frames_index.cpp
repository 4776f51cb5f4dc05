#include "cellsph/io/frames_index.hpp"

#include <cstdio>
#include <fstream>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/io/number_format.hpp"

namespace cellsph {

namespace {
constexpr std::string_view kFormatOrder[] = {"vtu", "ply", "csv"};

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> parts;
  std::size_t a = 0;
  while (true) {
    const auto b = s.find(sep, a);
    parts.push_back(s.substr(a, b == std::string_view::npos ? std::string_view::npos : b - a));
    if (b == std::string_view::npos) break;
    a = b + 1;
  }
  return parts;
}
}  // namespace

std::vector<std::string> OutputFormats::names() const {
  std::vector<std::string> r;
  if (vtu) r.emplace_back("vtu");
  if (ply) r.emplace_back("ply");
  if (csv) r.emplace_back("csv");
  return r;
}

OutputFormats parse_output_formats(std::string_view list, std::string_view what) {
  OutputFormats f;
  if (list.empty()) return f;
  for (const auto item : split(list, ',')) {
    bool* flag = item == "vtu" ? &f.vtu : item == "ply" ? &f.ply : item == "csv" ? &f.csv : nullptr;
    if (!flag)
      throw InputError(std::string(what) + ": unknown output format '" + std::string(item) +
                       "' (expected a comma-separated subset of vtu,ply,csv)");
    if (*flag)
      throw InputError(std::string(what) + ": output format '" + std::string(item) + "' given twice");
    *flag = true;
  }
  return f;
}

std::string frame_file_name(std::size_t frame, std::string_view extension, std::string_view stem) {
  char digits[32];
  std::snprintf(digits, sizeof(digits), "%05zu", frame);
  std::string name(stem);
  name += digits;
  name += '.';
  name += extension;
  return name;
}

FramesIndex::FramesIndex(std::filesystem::path path, std::vector<std::string> formats,
                         std::vector<FrameRow> rows)
    : path_(std::move(path)), formats_(std::move(formats)), rows_(std::move(rows)) {
  // Keep the contract: known formats, canonical order.
  std::size_t next = 0;
  for (const auto& f : formats_) {
    while (next < std::size(kFormatOrder) && kFormatOrder[next] != f) ++next;
    CELLSPH_CHECK(next < std::size(kFormatOrder),
                  "frames.csv format columns must be a subset of vtu,ply,csv in "
                  "that order, got '"
                      << f << "'");
    ++next;
  }
}

void FramesIndex::add(FrameRow row) {
  CELLSPH_CHECK(row.files.size() == formats_.size(), "frame " << row.frame << " has " << row.files.size()
                                                              << " files for " << formats_.size()
                                                              << " formats");
  rows_.push_back(std::move(row));
  write();
}

void FramesIndex::write() const {
  std::string s = "frame,time";
  for (const auto& f : formats_) s += "," + f;
  s += '\n';
  for (const auto& r : rows_) {
    io::append_number(s, r.frame);
    s += ',';
    io::append_number(s, r.time);
    for (const auto& f : r.files) s += "," + f;
    s += '\n';
  }
  write_file_atomic(path_, s);
}

FramesIndex read_frames_index(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read frame index '" + path.string() + "'");
  std::string line;
  if (!std::getline(in, line))
    throw InputError(std::string("'") + path.string() + "': empty file, expected header 'frame,time,...'");
  const auto head = split(line, ',');
  if (head.size() < 2 || head[0] != "frame" || head[1] != "time")
    throw InputError(std::string("'") + path.string() +
                     "' row 1: header must start with 'frame,time', got '" + line + "'");
  std::vector<std::string> formats;
  std::size_t next = 0;
  for (std::size_t c = 2; c < head.size(); ++c) {
    while (next < std::size(kFormatOrder) && kFormatOrder[next] != head[c]) ++next;
    if (next == std::size(kFormatOrder))
      throw InputError(std::string("'") + path.string() + "' row 1 column " + std::to_string(c + 1) +
                       ": unexpected column '" + std::string(head[c]) +
                       "' (format columns are vtu, ply, csv in that order)");
    formats.emplace_back(head[c]);
    ++next;
  }
  std::vector<FrameRow> rows;
  std::size_t row_no = 1;
  while (std::getline(in, line)) {
    ++row_no;
    if (line.empty()) continue;
    const auto cells = split(line, ',');
    const auto where = std::string("'") + path.string() + "' row " + std::to_string(row_no);
    if (cells.size() != head.size())
      throw InputError(where + ": " + std::to_string(cells.size()) + " columns, header has " +
                       std::to_string(head.size()));
    FrameRow r;
    if (!io::parse_number(cells[0], r.frame))
      throw InputError(where + " column 'frame': not a frame number: '" + std::string(cells[0]) + "'");
    if (!io::parse_number(cells[1], r.time))
      throw InputError(where + " column 'time': not a number: '" + std::string(cells[1]) + "'");
    for (std::size_t c = 2; c < cells.size(); ++c) r.files.emplace_back(cells[c]);
    rows.push_back(std::move(r));
  }
  return FramesIndex(path, std::move(formats), std::move(rows));
}

}  // namespace cellsph
