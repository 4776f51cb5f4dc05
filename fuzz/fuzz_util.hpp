#pragma once
// Shared by the libFuzzer harnesses of fuzz/ (built only with -DCELLSPH_FUZZ=ON, see docs/fuzzing.md).
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include <omp.h>

#include "cellsph/core/error.hpp"

namespace cellsph::fuzz {

// A file that lives in memory (memfd), reachable by a path for the readers that take one, so a harness
// never touches the disk and leaves nothing behind.
class MemFile {
 public:
  explicit MemFile(const char* name) : fd_(memfd_create(name, 0)) {
    if (fd_ < 0) {
      std::perror("memfd_create");
      std::abort();
    }
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~MemFile() { close(fd_); }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  // Replaces the content.
  void set(std::string_view bytes) {
    if (ftruncate(fd_, 0) != 0 ||
        pwrite(fd_, bytes.data(), bytes.size(), 0) != static_cast<ssize_t>(bytes.size())) {
      std::perror("memfd write");
      std::abort();
    }
  }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  int fd_;
  std::filesystem::path path_;
};

// One thread: a fuzzer input is small, and libFuzzer's timing and leak checks want one thread.
inline void single_thread() {
  omp_set_num_threads(1);
}

}  // namespace cellsph::fuzz
