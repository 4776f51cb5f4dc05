#include "cellsph/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <streambuf>
#include <system_error>
#include <vector>

#include "cellsph/core/error.hpp"

namespace cellsph {

namespace {

// ---- fault injection -------------------------------------------------------------------------------
std::atomic<std::int64_t> g_fault_after{-1};  // files still allowed before faults start; < 0: none
std::atomic<std::int64_t> g_opened{0};
std::atomic<int> g_fault_stage{0};
std::atomic<bool> g_fault_set_by_test{false};
std::once_flag g_env_once;

void read_fault_env() {
  if (g_fault_set_by_test) return;
  const char* v = std::getenv("CELLSPH_FAIL_WRITE_AFTER");
  if (!v || !*v) return;
  char* end = nullptr;
  const long long n = std::strtoll(v, &end, 10);
  WriteFaultStage stage = WriteFaultStage::Write;
  const std::string_view rest(end);
  if (rest == ":fsync")
    stage = WriteFaultStage::Fsync;
  else if (rest == ":close")
    stage = WriteFaultStage::Close;
  else if (rest == ":rename")
    stage = WriteFaultStage::Rename;
  else if (!rest.empty() && rest != ":write")
    throw InputError(
        std::string("CELLSPH_FAIL_WRITE_AFTER: expected N or N:write|fsync|close|rename, got '") + v + "'");
  if (end == v || n < 0)
    throw InputError(std::string("CELLSPH_FAIL_WRITE_AFTER: expected a count >= 0, got '") + v + "'");
  g_fault_stage = static_cast<int>(stage);
  g_opened = 0;
  g_fault_after = n;
}

// Whether the file opened now is to fail, and where.
bool take_fault_ticket(WriteFaultStage& stage) {
  std::call_once(g_env_once, read_fault_env);
  const std::int64_t after = g_fault_after.load();
  if (after < 0) return false;
  const std::int64_t ticket = g_opened.fetch_add(1);
  stage = static_cast<WriteFaultStage>(g_fault_stage.load());
  return ticket >= after;
}

std::filesystem::path temp_name(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  auto name = target.filename().string();
  name = "." + name + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  return target.parent_path() / name;
}

}  // namespace

// A stream buffer over a file descriptor that loops over short writes, retries on EINTR, and keeps the
// first error (errno) so the message can give the system's reason: std::ofstream loses it.
class AtomicFile::FdBuf : public std::streambuf {
 public:
  FdBuf(int fd, bool fault, WriteFaultStage stage) : fd_(fd), fault_(fault), stage_(stage), buf_(1 << 16) {
    setp(buf_.data(), buf_.data() + buf_.size());
  }
  ~FdBuf() override {
    if (fd_ >= 0) ::close(fd_);
  }
  FdBuf(const FdBuf&) = delete;
  FdBuf& operator=(const FdBuf&) = delete;

  [[nodiscard]] int error() const { return error_; }
  [[nodiscard]] bool injected() const { return injected_; }

  // Writes what is buffered, then syncs and closes. Returns false with error() set on any failure.
  bool finish() {
    if (!drain()) return false;
    if (fault_ && stage_ == WriteFaultStage::Fsync) return injected(EIO);
    if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) return failed(errno);  // EINVAL: no sync here
    const int fd = fd_;
    fd_ = -1;
    if (fault_ && stage_ == WriteFaultStage::Close) {
      ::close(fd);
      return injected(EIO);
    }
    if (::close(fd) != 0 && errno != EINTR) return failed(errno);
    return true;
  }
  // Whether this file's rename is to fail (fault injection).
  bool rename_fault() {
    if (!(fault_ && stage_ == WriteFaultStage::Rename)) return false;
    injected(ENOSPC);
    return true;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n <= epptr() - pptr()) {
      std::memcpy(pptr(), s, static_cast<std::size_t>(n));
      pbump(static_cast<int>(n));
      return n;
    }
    // Large blocks go straight to the file.
    if (!drain() || !write_all(s, static_cast<std::size_t>(n))) return 0;
    return n;
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    const auto n = static_cast<std::size_t>(pptr() - pbase());
    const bool ok = write_all(pbase(), n);
    setp(buf_.data(), buf_.data() + buf_.size());
    return ok;
  }
  bool write_all(const char* p, std::size_t n) {
    if (error_) return false;
    if (fault_ && stage_ == WriteFaultStage::Write && n > 0) {
      // A full disk: part of the block lands, then the device is out of space.
      (void)!::write(fd_, p, n / 2);
      return injected(ENOSPC);
    }
    while (n > 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        return failed(errno);
      }
      if (w == 0) return failed(EIO);  // no progress and no error: do not spin
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }
  bool failed(int err) {
    if (!error_) error_ = err ? err : EIO;
    return false;
  }
  bool injected(int err) {
    injected_ = true;
    return failed(err);
  }

  int fd_;
  bool fault_;
  WriteFaultStage stage_;
  std::vector<char> buf_;
  int error_ = 0;
  bool injected_ = false;
};

AtomicFile::AtomicFile(std::filesystem::path target, bool /*binary*/)
    : target_(std::move(target)), temp_(temp_name(target_)), out_(nullptr) {
  WriteFaultStage stage = WriteFaultStage::Write;
  const bool fault = take_fault_ticket(stage);
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    committed_ = true;  // nothing to remove
    fail("cannot create a temporary file beside it (" + temp_.filename().string() + ")", err);
  }
  buf_ = std::make_unique<FdBuf>(fd, fault, stage);
  out_.rdbuf(buf_.get());
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    buf_.reset();  // closes the descriptor
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::fail(const std::string& what, int err) {
  std::string msg = "cannot write '" + target_.string() + "': ";
  if (!what.empty()) msg += what + ": ";
  msg += std::generic_category().message(err);
  if (buf_ && buf_->injected()) msg += " (injected by CELLSPH_FAIL_WRITE_AFTER)";
  throw WriteError(msg);
}

void AtomicFile::commit() {
  out_.flush();
  // A failure in any earlier write, the flush, fsync or close: the reason is the first errno seen.
  if (!out_ || !buf_->finish()) fail("", buf_->error() ? buf_->error() : EIO);
  std::error_code ec;
  if (buf_->rename_fault())
    ec.assign(buf_->error(), std::generic_category());
  else
    std::filesystem::rename(temp_, target_, ec);
  if (ec) fail("renaming " + temp_.filename().string() + " into place", ec.value());
  committed_ = true;
}

void write_file_atomic(const std::filesystem::path& target, std::string_view contents) {
  AtomicFile f(target, true);
  f.stream().write(contents.data(), static_cast<std::streamsize>(contents.size()));
  f.commit();
}

bool is_atomic_temp_name(std::string_view name) {
  // ".NAME.tmp<digits>_<digits>"
  if (name.size() < 8 || name[0] != '.') return false;
  const auto at = name.rfind(".tmp");
  if (at == std::string_view::npos || at == 0) return false;
  const auto tail = name.substr(at + 4);
  const auto us = tail.find('_');
  if (us == std::string_view::npos || us == 0 || us + 1 == tail.size()) return false;
  for (std::size_t k = 0; k < tail.size(); ++k)
    if (k != us && (tail[k] < '0' || tail[k] > '9')) return false;
  return true;
}

void set_write_fault(std::int64_t after, WriteFaultStage stage) {
  g_fault_set_by_test = true;
  g_fault_stage = static_cast<int>(stage);
  g_opened = 0;
  g_fault_after = after;
}

}  // namespace cellsph
