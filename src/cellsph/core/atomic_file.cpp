#include "cellsph/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <system_error>

#include "cellsph/core/error.hpp"

namespace cellsph {

namespace {
std::filesystem::path temp_name(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  auto name = target.filename().string();
  name = "." + name + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  return target.parent_path() / name;
}
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target, bool binary)
    : target_(std::move(target)), temp_(temp_name(target_)) {
  out_.open(temp_,
            binary ? std::ios::out | std::ios::binary | std::ios::trunc : std::ios::out | std::ios::trunc);
  if (!out_)
    throw InputError("cannot write file '" + target_.string() + "' (temporary '" + temp_.string() + "')");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw InputError("error while writing '" + target_.string() + "'");
  out_.close();
  // Make the bytes durable before the rename publishes them.
  const int fd = ::open(temp_.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec)
    throw InputError("cannot rename '" + temp_.string() + "' to '" + target_.string() + "': " + ec.message());
  committed_ = true;
}

void write_file_atomic(const std::filesystem::path& target, std::string_view contents) {
  AtomicFile f(target, true);
  f.stream().write(contents.data(), static_cast<std::streamsize>(contents.size()));
  f.commit();
}

}  // namespace cellsph
