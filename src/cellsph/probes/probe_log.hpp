#pragma once
// probes.csv: `time,COLUMN1,COLUMN2,...` then one row per sample (%.17g, so a value read back is the
// value written; an empty field where a probe had no fluid within reach). The whole file is rewritten
// atomically on flush(), so a run killed at any moment leaves the last flushed file whole. A resume
// keeps the rows up to its checkpoint's time and drops the rest (a killed run may have sampled past its
// last checkpoint), so the file of a resumed run is the file of an uninterrupted one.
#include <filesystem>
#include <string>
#include <vector>

namespace cellsph {

class ProbeLog {
 public:
  ProbeLog(std::filesystem::path file, std::vector<std::string> columns);

  // Reads an existing file for a resume: its header must be this log's, every row must have every
  // column; rows with time <= t_end are kept. Throws InputError naming the file and line otherwise.
  // Writes nothing. A missing file is an empty log (a run killed before its first flush).
  void resume(double t_end);

  void add(double time, const std::vector<double>& values);
  // Writes the file (atomically) if rows were added since the last flush. Throws WriteError.
  void flush();

  [[nodiscard]] std::size_t rows() const { return rows_.size(); }
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  [[nodiscard]] std::string header() const;
  std::filesystem::path file_;
  std::vector<std::string> columns_;
  std::vector<std::string> rows_;
  bool dirty_ = true;
};

}  // namespace cellsph
