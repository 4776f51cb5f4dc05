#pragma once
// Thin OpenMP drivers. Work is split statically so that the split, and with it every result,
// depends only on the thread count chosen by the user.
#include <cstddef>
#include <cstdint>

#include <omp.h>

namespace cellsph {

inline int max_threads() {
  return omp_get_max_threads();
}
inline int thread_id() {
  return omp_get_thread_num();
}

// Sets the number of threads for the lifetime of the object, restoring the previous value after.
class ScopedThreads {
 public:
  explicit ScopedThreads(int n) : previous_(omp_get_max_threads()) {
    if (n > 0) omp_set_num_threads(n);
  }
  ~ScopedThreads() { omp_set_num_threads(previous_); }
  ScopedThreads(const ScopedThreads&) = delete;
  ScopedThreads& operator=(const ScopedThreads&) = delete;

 private:
  int previous_;
};

// f(i) for i in [0, n), statically scheduled.
template <class F>
void parallel_for(std::size_t n, F&& f) {
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

// f(begin, end) over contiguous chunks of at most `grain` elements, dynamically scheduled.
// Use only where the result does not depend on which thread runs which chunk.
template <class F>
void parallel_chunks(std::size_t n, std::size_t grain, F&& f) {
  if (grain == 0) grain = 1;
  const auto chunks = static_cast<std::int64_t>((n + grain - 1) / grain);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t c = 0; c < chunks; ++c) {
    const std::size_t b = static_cast<std::size_t>(c) * grain;
    const std::size_t e = b + grain < n ? b + grain : n;
    f(b, e);
  }
}

}  // namespace cellsph
