#pragma once
// Least-significant-digit radix sort for 64-bit keys (paper section 4.2: the Cell Indexing keys of
// eq. 17 are sorted in linear time).
//
// Parallel with OpenMP: each thread histograms a contiguous block of the input, an exclusive
// prefix sum over (digit, thread) gives every thread its own write position per digit, and each
// thread scatters its block in input order. Because blocks are taken in order and digits
// bucket-major, every pass is stable, so the result is the unique stable order and does not depend
// on the thread count.
//
// Digit passes are only made over bits that vary: bits where OR and AND of all keys agree are the
// same in every key and cannot change the order. Keys that use few bits sort in few passes.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace cellsph {

// Widest digit a pass uses; 2^11 counters per thread still sit in L1/L2.
inline constexpr int kRadixMaxDigitBits = 11;

// Sorts `keys` ascending, stably, by the bits [begin_bit, end_bit) of each key (other bits are
// ignored for the order but moved with their key). `scratch` is resized to keys.size() and used as
// the second buffer; on return it holds unspecified values. Both vectors may be swapped internally.
void radix_sort(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch, int begin_bit = 0,
                int end_bit = 64);

// Same on the caller's buffers, which keep their memory: sorts the keys with scratch (at least as
// long) as the second buffer and returns the one that holds the sorted keys (keys.data() or
// scratch.data(), by the number of passes).
std::uint64_t* radix_sort(std::span<std::uint64_t> keys, std::span<std::uint64_t> scratch, int begin_bit = 0,
                          int end_bit = 64);

// Same, moving one 32-bit payload with each key (stable: equal keys keep their payload order).
void radix_sort_pairs(std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>& payload,
                      std::vector<std::uint64_t>& key_scratch, std::vector<std::uint32_t>& payload_scratch,
                      int begin_bit = 0, int end_bit = 64);

// Number of digit passes radix_sort would make for these keys (for tests and statistics).
int radix_sort_passes(const std::vector<std::uint64_t>& keys, int begin_bit = 0, int end_bit = 64);

}  // namespace cellsph
