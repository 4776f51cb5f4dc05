#pragma once
// Output files are written atomically: into a temporary file beside the target, flushed, synced, then
// renamed over it. A run killed at any moment leaves either the old file or the new one (and at worst a
// stray temporary file, named by is_atomic_temp_name()).
//
// Every failure on the way (open, a short or failed write, fsync, close, rename) throws WriteError naming
// the target and the system's reason, and removes the temporary file; the target is then untouched.
//
// Fault injection for tests: CELLSPH_FAIL_WRITE_AFTER=N[:STAGE] in the environment (read once, at the
// first AtomicFile) lets the first N atomic files of the process be written and makes every later one fail
// at STAGE: `write` (default: half of the first block is written, then ENOSPC), `fsync` (EIO), `close`
// (EIO) or `rename` (ENOSPC), as a full disk would. set_write_fault() does the same from a test.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

namespace cellsph {

class AtomicFile {
 public:
  // `binary` is kept for the callers' documentation: the stream never translates line ends (POSIX).
  explicit AtomicFile(std::filesystem::path target, bool binary = false);
  ~AtomicFile();  // removes the temporary file if commit() was not called
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  // Flushes, syncs and renames the temporary file over the target. Throws WriteError on any failure.
  void commit();

 private:
  class FdBuf;
  [[noreturn]] void fail(const std::string& what, int err);
  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::unique_ptr<FdBuf> buf_;
  std::ostream out_;
  bool committed_ = false;
};

void write_file_atomic(const std::filesystem::path& target, std::string_view contents);

// True for the names AtomicFile gives its temporary files (".NAME.tmp<pid>_<n>"): what a killed run can
// leave behind, and a resume may remove.
bool is_atomic_temp_name(std::string_view filename);

enum class WriteFaultStage { Write, Fsync, Close, Rename };

// Test hook: the next `after` atomic files succeed, every later one fails at `stage`. after < 0: no faults.
void set_write_fault(std::int64_t after, WriteFaultStage stage = WriteFaultStage::Write);

}  // namespace cellsph
