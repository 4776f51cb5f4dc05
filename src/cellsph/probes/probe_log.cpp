#include "cellsph/probes/probe_log.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"

namespace cellsph {

ProbeLog::ProbeLog(std::filesystem::path file, std::vector<std::string> columns)
    : file_(std::move(file)), columns_(std::move(columns)) {}

std::string ProbeLog::header() const {
  std::string h = "time";
  for (const auto& c : columns_) h.append(",").append(c);
  return h;
}

void ProbeLog::resume(double t_end) {
  rows_.clear();
  dirty_ = true;
  std::ifstream in(file_);
  if (!in) {
    if (std::filesystem::exists(file_))
      throw InputError("probes file '" + file_.string() + "': cannot be read");
    return;
  }
  auto bad = [&](std::size_t line, const std::string& what) {
    throw InputError("probes file '" + file_.string() + "', line " + std::to_string(line) + ": " + what);
  };
  std::string line;
  if (!std::getline(in, line) || line != header())
    bad(1, "header '" + line + "' is not this scene's '" + header() + "' (the scene's probes changed?)");
  for (std::size_t n = 2; std::getline(in, line); ++n) {
    std::size_t fields = 1;
    for (char c : line) fields += c == ',' ? 1 : 0;
    if (fields != columns_.size() + 1)
      bad(n, std::to_string(fields) + " fields, the header has " + std::to_string(columns_.size() + 1));
    const std::string first = line.substr(0, line.find(','));
    char* end = nullptr;
    const double t = std::strtod(first.c_str(), &end);
    if (first.empty() || end != first.c_str() + first.size() || !std::isfinite(t))
      bad(n, "time '" + first + "' is not a number");
    if (t <= t_end) rows_.push_back(line);
  }
}

void ProbeLog::add(double time, const std::vector<double>& values) {
  std::string row;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", time);
  row += buf;
  for (double v : values) {
    row += ',';
    if (std::isnan(v)) continue;
    std::snprintf(buf, sizeof buf, "%.17g", v);
    row += buf;
  }
  rows_.push_back(std::move(row));
  dirty_ = true;
}

void ProbeLog::flush() {
  if (!dirty_) return;
  std::string text = header() + "\n";
  for (const auto& r : rows_) text.append(r).append("\n");
  write_file_atomic(file_, text);
  dirty_ = false;
}

}  // namespace cellsph
