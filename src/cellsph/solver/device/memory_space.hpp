#pragma once
// Memory spaces of the device backends and the arrays that live in them.
//  * HostDeviceSpace: host memory used as a device would be (separate allocations, every transfer an
//    explicit copy through the functions below), so the device bookkeeping runs, and is tested, without
//    a GPU (under ASan in CI: a field read before its copy, or past its end, is caught there).
//  * CudaSpace: CUDA device memory (cudaMalloc, cudaMemcpy), defined in cuda/cuda_runtime.cu; declared
//    here without any CUDA type so that host code can name it.
// DeviceParticles<Dim, Real, Space> is the particle storage (particles.hpp) in a space; upload_particles()
// and download_particles() copy every field over the one field list (for_each_field_of), never field by
// field.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string_view>
#include <utility>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

struct HostDeviceSpace {
  static constexpr const char* name = "host-device";
  // Bytes moved each way since the program started (tests check that steps leave the state here).
  static inline std::atomic<std::uint64_t> bytes_to_device{0}, bytes_to_host{0};
  static void* allocate(std::size_t bytes) {
    void* p = std::malloc(bytes);
    if (!p) throw std::bad_alloc();
    return p;
  }
  static void release(void* p) noexcept { std::free(p); }
  static void to_device(void* dst, const void* src, std::size_t bytes) {
    bytes_to_device += bytes;
    std::memcpy(dst, src, bytes);
  }
  static void to_host(void* dst, const void* src, std::size_t bytes) {
    bytes_to_host += bytes;
    std::memcpy(dst, src, bytes);
  }
  static void on_device(void* dst, const void* src, std::size_t bytes) { std::memcpy(dst, src, bytes); }
  static void zero(void* dst, std::size_t bytes) { std::memset(dst, 0, bytes); }
};

// Every call is checked: a failure throws DeviceError naming the CUDA call, the file and the line.
struct CudaSpace {
  static constexpr const char* name = "cuda";
  static void* allocate(std::size_t bytes);
  static void release(void* p) noexcept;
  static void to_device(void* dst, const void* src, std::size_t bytes);
  static void to_host(void* dst, const void* src, std::size_t bytes);
  static void on_device(void* dst, const void* src, std::size_t bytes);
  static void zero(void* dst, std::size_t bytes);
};

// A failed device call (CUDA runtime error): the message names the call, file and line.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An array of n trivially copyable T in `Space`, owned (move-only). resize() keeps nothing (device
// arrays are refilled by passes or copies); it reallocates only to grow.
template <class T, class Space>
class DeviceArray {
 public:
  using value_type = T;
  DeviceArray() = default;
  explicit DeviceArray(std::size_t n) { resize(n); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  DeviceArray(DeviceArray&& o) noexcept
      : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)), cap_(std::exchange(o.cap_, 0)) {}
  DeviceArray& operator=(DeviceArray&& o) noexcept {
    if (this != &o) {
      Space::release(p_);
      p_ = std::exchange(o.p_, nullptr);
      n_ = std::exchange(o.n_, 0);
      cap_ = std::exchange(o.cap_, 0);
    }
    return *this;
  }
  ~DeviceArray() { Space::release(p_); }

  void resize(std::size_t n) {
    if (n > cap_) {
      Space::release(p_);
      p_ = nullptr;
      cap_ = 0;
      p_ = static_cast<T*>(Space::allocate(n * sizeof(T)));
      cap_ = n;
    }
    n_ = n;
  }
  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] T* data() { return p_; }
  [[nodiscard]] const T* data() const { return p_; }
  void zero() {
    if (n_) Space::zero(p_, n_ * sizeof(T));
  }
  // Whole-array transfers (sizes must match).
  void upload(const T* host, std::size_t n) {
    resize(n);
    if (n) Space::to_device(p_, host, n * sizeof(T));
  }
  void download(T* host) const {
    if (n_) Space::to_host(host, p_, n_ * sizeof(T));
  }
  // One element to the host (a count or a total after a scan).
  [[nodiscard]] T get(std::size_t k) const {
    CELLSPH_CHECK(k < n_, "device array: element " << k << " of " << n_);
    T v;
    Space::to_host(&v, p_ + k, sizeof(T));
    return v;
  }

 private:
  T* p_ = nullptr;
  std::size_t n_ = 0;
  std::size_t cap_ = 0;
};

template <class Space>
struct ArrayIn {
  template <class T>
  using type = DeviceArray<T, Space>;
};

template <int Dim, class Real, class Space>
using DeviceParticles = BasicParticles<Dim, Real, ArrayIn<Space>::template type>;

// Host -> device, every field (the mirror is resized to the host's count).
template <int Dim, class Real, template <class> class Array>
void upload_particles(const Particles<Dim, Real>& host, BasicParticles<Dim, Real, Array>& dev) {
  Particles<Dim, Real>::for_each_field_of(
      [n = host.size()](std::string_view name, const auto& h, auto& d) {
        CELLSPH_CHECK(h.size() == n,
                      "particles: field '" << name << "' has " << h.size() << " entries for " << n);
        d.upload(h.data(), n);
      },
      host, dev);
}

// Device -> host, every field.
template <int Dim, class Real, template <class> class Array>
void download_particles(const BasicParticles<Dim, Real, Array>& dev, Particles<Dim, Real>& host) {
  Particles<Dim, Real>::for_each_field_of(
      [](std::string_view, const auto& d, auto& h) {
        h.resize(d.size());
        d.download(h.data());
      },
      dev, host);
}

}  // namespace cellsph
