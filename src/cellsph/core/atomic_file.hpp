#pragma once
// Output files are written atomically: into a temporary file beside the target, flushed, then
// renamed over it. A run killed at any moment leaves either the old file or the new one.
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace cellsph {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target, bool binary = false);
  ~AtomicFile();  // removes the temporary file if commit() was not called
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  // Flushes, syncs and renames the temporary file over the target. Throws on I/O failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::ofstream out_;
  bool committed_ = false;
};

void write_file_atomic(const std::filesystem::path& target, std::string_view contents);

}  // namespace cellsph
