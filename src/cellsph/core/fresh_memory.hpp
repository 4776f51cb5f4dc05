#pragma once
// Large arrays that are written in full before they are read (a search's positions and ids in key
// order, its work buffer, the neighbour lists): first-touching fresh memory costs a page fault for
// every 4 KiB page (on this project's VM about 10 us each: 24 MB of positions took ~60 ms, more than
// the rest of a warm build at 10^6 points), and std::vector's resize adds a zero fill on one thread.
// So: ask Linux for 2 MiB pages (transparent huge pages in "madvise" mode; only a hint), and leave
// the entries default-initialised (no zero fill) where the code writes every one of them anyway.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace cellsph {

// Asks Linux to back the whole 2 MiB pages inside [p, p + bytes) with huge pages. Call it before the
// memory is first touched; regions under 4 MiB are left alone.
inline void advise_huge_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{1} << 21;
  if (bytes < 2 * kHuge) return;
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t b = (a + kHuge - 1) & ~(kHuge - 1), e = (a + bytes) & ~(kHuge - 1);
  if (e > b) madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#endif
}

// std::allocator, except that a value-less construct() default-initialises (resize() leaves
// trivial entries unwritten) and large blocks are advised to huge pages.
template <class T>
struct FreshAllocator {
  using value_type = T;
  FreshAllocator() = default;
  template <class U>
  explicit FreshAllocator(const FreshAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    T* p = std::allocator<T>{}.allocate(n);
    advise_huge_pages(p, n * sizeof(T));
    return p;
  }
  void deallocate(T* p, std::size_t n) noexcept { std::allocator<T>{}.deallocate(p, n); }

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  friend bool operator==(const FreshAllocator&, const FreshAllocator<U>&) noexcept {
    return true;
  }
};

// A vector whose resize() does not zero its new entries: every one must be written before it is read.
template <class T>
using FreshVector = std::vector<T, FreshAllocator<T>>;

}  // namespace cellsph
