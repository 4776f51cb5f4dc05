#pragma once
// Cell Indexing (paper section 4.2): neighbour search by sorting keys that pack the particle index
// and its cell coordinates (eq. 17), then streaming through the sorted keys with one cursor per
// H-mask cell. No hash table and no dense grid: memory is O(n) whatever the bounding box.
//
//   key(n, i, j, k) = n + 2^I i + 2^(I+J) j + 2^(I+J+K) k,   2^I > N, 2^J > cells along x, ...  (eq. 17)
//
// Sorting the keys orders particles by cell (last axis slowest), then by index. The H-mask (see
// hmask.hpp) is ordered the same way, so for consecutive home cells the key of each mask cell only
// grows: each mask cell keeps a cursor into the sorted cells that only moves forward.
//
// Cell coordinates are shifted by the mask radius so that home + offset never leaves its row: the
// key of each mask cell relative to the home cell is one constant (deltas_), and targets off the
// grid find no cell. When I + cell bits exceed 64 the keys widen to a 64-bit cell key sorted with a
// 32-bit index payload (same order); an axis that would need more bits than that is cut at its
// last cell, which stays exact (see build()).
//
// Speed: the candidates of a home cell (its mask cells, adjacent ones merged) are copied once into
// a contiguous block shared by the cell's particles; each particle tests the block 8 (AVX2) or 4
// (SSE2) at a time (cell_index_simd.hpp: the loops at each width, chosen at run time), in float whatever Real
// is (a double search keeps its positions in float too, half the bytes), and walks the set bits of the hit
// mask, with no branch per candidate. find_all counts, keeping every particle's hit masks (blocks of up to
// 256 candidates in a work buffer, longer ones in a spill per traversal chunk), then fills the rows from them
// with no second distance test, and sorts each row of up to 64 in registers (sort_network.hpp), up to 96 by
// rank.
//
// Exactness: the neighbour test is distance2(x[i], x[j]) <= h[i]^2 in Real, the same expression as
// the all-pairs reference; the mask only decides which candidates reach that test, and it is built
// from exact cell geometry with the inflated cell size of hmask.hpp. A double search decides in
// float only the candidates that float cannot misjudge, and tests the rest (those within a thin
// band around h) in double from the caller's positions (hits64): so build's x must stay alive and
// unchanged until the last query of that build.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <sstream>
#include <type_traits>
#include <vector>

#include <omp.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#include "cellsph/core/error.hpp"
#include "cellsph/core/fresh_memory.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/cell_index_simd.hpp"
#include "cellsph/neighbors/csr_builder.hpp"
#include "cellsph/neighbors/hmask.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"
#include "cellsph/neighbors/radix_sort.hpp"

namespace cellsph {

template <int Dim, class Real>
class CellIndex {
 public:
  using Point = Vec<Dim, Real>;

  explicit CellIndex(const SearchOptions& opt = {})
      : subdivision_(opt.subdivision), sorted_rows_(opt.sorted_rows), zero_rows_(opt.zero_support_rows) {
    if (subdivision_ < 1) {
      std::ostringstream os;
      os << "cell-index: subdivision H must be >= 1, got " << subdivision_;
      throw InputError(os.str());
    }
  }

  // Forces the wide key layout (64-bit cell key + 32-bit index payload) even when eq. 17's packed
  // key would fit. For tests and for measuring what the packing saves.
  void force_wide_keys(bool on) { force_wide_ = on; }

  // Caps the blocks sorted by id whose order find_all keeps between its passes (at most 2^16, the
  // default); longer ones are sorted again by the fill pass. For tests: blocks of 2^16 candidates
  // cost 2^32 distance tests each against the all-pairs reference.
  void limit_kept_order(std::uint32_t n) { kept_order_max_ = std::min(n, kKeptOrderMax); }

  // x is read again by the queries of a double search (the exact test near h): it must outlive them,
  // unchanged, as for AllPairs. h is copied.
  void build(std::span<const Point> x, std::span<const Real> h) {
    CELLSPH_CHECK(h.size() == x.size(), "support lengths " << h.size() << " != points " << x.size());
    build(x, h, Real(0));
  }

  // One support length for all particles: no array of them is read or kept.
  void build(std::span<const Point> x, Real radius) { build(x, {}, radius); }

 private:
  // h empty: every particle's support is radius.
  void build(std::span<const Point> x, std::span<const Real> h, Real radius) {
    clear();
    n_ = x.size();
    if (n_ == 0) return;
    if (n_ > std::numeric_limits<std::uint32_t>::max()) {
      std::ostringstream os;
      os << "cell-index: " << n_ << " particles exceed the 32-bit particle index (at most "
         << std::numeric_limits<std::uint32_t>::max() << ")";
      throw CapacityError(os.str());
    }
    const Bounds b = bounds(x, h, radius);
    hmax_ = b.hmax;
    uniform_h_ = b.hmin == b.hmax;
    const int pad = set_cells_and_mask(b);
    for (int k = 0; k < Dim; ++k) origin_[k] = double(b.lo[k]);
    if constexpr (kBand) set_float_band(b, x);
    set_key_layout(b, pad);
    sort_particles(x, pad);
    gather(x, h);
  }

 public:
  // Calls f(i, j, r2) for every ordered pair with j in N(i); all calls for one i come from one
  // thread, consecutively, j in key order. Returns the number of distance tests.
  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    return traverse<true>([&](std::uint32_t p, const Block& blk, const std::uint64_t*) {
      const std::uint32_t i = ids_[p];
      const Probe pr = probe(p);
      for_each_hit(p, blk, pr, [&](std::uint32_t t, std::uint32_t j) {
        if constexpr (kBand)
          f(i, j, distance2(xd_[i], xd_[j]));
        else
          f(i, j, block_dist2(blk, pr.x, t));
      });
    });
  }

  // Canonical CSR lists (rows ascending) in two traversals, count then fill, so that nothing but
  // the lists is allocated at list size. Each row is sorted while it is still in cache. Uses the
  // index's work buffer: not to be called from two threads at once on one index.
  std::uint64_t find_all(NeighborList& out) const {
    // count_rows writes every row length: only the leading 0 needs a value.
    out.offsets.resize(n_ + 1);
    out.offsets[0] = 0;
    if (n_ == 0) {
      out.indices.clear();
      return 0;
    }
    // The count pass keeps every particle's hit masks (see traverse), so the fill pass tests no
    // distance again: it only packs them.
    const std::uint64_t candidates = count_rows(out.offsets.data() + 1, true);
    for (std::size_t i = 0; i < n_; ++i) out.offsets[i + 1] += out.offsets[i];
    const std::uint64_t total = out.offsets[n_];
    if (out.indices.capacity() < total || out.indices.capacity() > total + total / 2) {
      out.indices.clear();
      out.indices.shrink_to_fit();  // never hold the old and the new lists at once
      out.indices.reserve(total);
      advise_huge_pages(out.indices.data(), total * sizeof(std::uint32_t));
    }
    out.indices.resize(total);
    std::uint32_t* idx = out.indices.data();
    const std::uint64_t* off = out.offsets.data();
    // always_inline (here and in count_rows): traverse calls its kernel from five places, and GCC 12
    // then keeps it out of line, a call with a stack frame per particle; inlined, the search takes
    // 8-10% less time (docs/benchmarks.md), as clang's inlining of it showed.
    auto fill = [&](std::uint32_t p, const Block& blk, const std::uint64_t* kept)
        __attribute__((always_inline)) {
      prefetch_rows(p, off, idx);
      const std::uint32_t i = ids_[p];
      std::uint32_t* row = idx + off[i];
      const std::uint64_t len = off[i + 1] - off[i];
      // Rows are gathered in a buffer (written 8 at a time, which would overrun the row into the
      // next one): typical ones on the stack and placed by rank, long ones in the block's scratch.
      std::uint32_t small[kRankSortMax + 8];
      std::uint32_t* buf = len <= kRankSortMax ? small : blk.scratch;
      const std::uint64_t c = pack_hits(kept, blk, buf);
      CELLSPH_CHECK(c == len,
                    "cell-index: fill pass found " << c << " neighbours of " << i << ", counted " << len);
      // Rows of a block sorted by index come out ascending already.
      const bool sort = sorted_rows_ && !blk.by_id;
      if (len > kRankSortMax) {
        if (sort) std::sort(buf, buf + len);
        std::memcpy(row, buf, len * sizeof(std::uint32_t));
      } else if (sort) {
        sort_row(buf, static_cast<std::uint32_t>(len), row);
      } else {
        if (len > 0)
          std::memcpy(row, buf, len * sizeof(std::uint32_t));  // row is null when no list has pairs
      }
    };
    if (sorted_rows_)
      traverse<true, true, Masks::Read>(fill);
    else
      traverse<true, false, Masks::Read>(fill);
    return candidates;
  }

  // The number of ordered pairs (i != j) and nothing else: find_all's first traversal, which counts each
  // row, without the second one that writes them. What the lists cost beyond it is the fill (benchmarks:
  // the compute floor of issue 15). `counts` gets one row length per particle.
  std::uint64_t count_pairs(std::vector<std::uint64_t>& counts) const {
    counts.assign(n_, 0);
    if (n_ > 0) count_rows(counts.data());
    std::uint64_t total = 0;
    for (const std::uint64_t c : counts) total += c;
    return total;
  }

  [[nodiscard]] std::size_t memory_bytes() const {
    std::size_t s = cells_.capacity() * sizeof(std::uint64_t) +
                    cell_start_.capacity() * sizeof(std::uint32_t) + hs_.capacity() * sizeof(Real) +
                    zero_cell_.capacity() + ids_.capacity() * sizeof(std::uint32_t) +
                    deltas_.capacity() * sizeof(std::uint64_t) + mask_.capacity() * sizeof(MaskCell<Dim>) +
                    work_.size() * sizeof(std::uint64_t);
    s += xs_.capacity() * sizeof(float);
    for (const auto& v : spill_) s += v.bytes();
    return s;
  }

  // Introspection for tests and statistics.
  [[nodiscard]] bool wide_keys() const { return wide_; }
  [[nodiscard]] int index_bits() const { return index_bits_; }
  [[nodiscard]] int cell_bits() const { return cell_bits_; }
  [[nodiscard]] std::size_t cell_count() const { return cells_.empty() ? 0 : cells_.size() - 1; }
  [[nodiscard]] std::size_t mask_size() const { return mask_.size(); }
  [[nodiscard]] double cell_size() const { return cell_size_; }

 private:
  // Each particle's neighbour count into counts[i] (one traversal, distance tests only); returns the
  // candidates tested. With store, every particle's hit masks (p itself left out) are kept for
  // find_all's fill pass, whose blocks are then in the same order (sorted by id as it sorts them).
  std::uint64_t count_rows(std::uint64_t* counts, bool store = false) const {
    auto count = [&](std::uint32_t p, const Block& blk, std::uint64_t* keep) __attribute__((always_inline)) {
      const Probe pr = probe(p);
      std::uint64_t c = 0;
      if (keep != nullptr) {
        for (std::uint32_t b = 0; b < blk.n; b += 64) {
          const std::uint64_t bits = hits_but_self(p, blk, pr, b);
          *keep++ = bits;
          c += popcount64(bits);
        }
      } else {
        for (std::uint32_t b = 0; b < blk.n; b += 64) c += popcount64(hits_but_self(p, blk, pr, b));
      }
      if (p + kAhead < n_) __builtin_prefetch(counts + ids_[p + kAhead], 1);
      counts[ids_[p]] = c;
    };
    if (!store) return traverse<false>(count);
    return sorted_rows_ ? traverse<false, true, Masks::Write>(count)
                        : traverse<false, false, Masks::Write>(count);
  }

  // Rows are written in key order but live in particle order: unless the input is in cell order,
  // each particle's offset and row are a cache miss that no hardware prefetcher predicts. The fill
  // pass asks for them ahead: the offset of the particle kAhead places on, and the row (first and
  // last line) of the one kAhead / 2 places on, whose offset was asked for before. always_inline:
  // GCC 12 judges a function whose only effects are prefetches pure and drops the call.
  static constexpr std::uint32_t kAhead = 16;
  [[gnu::always_inline]] void prefetch_rows(std::uint32_t p, const std::uint64_t* off,
                                            std::uint32_t* idx) const {
    if (p + kAhead < n_) __builtin_prefetch(off + ids_[p + kAhead]);
    if (p + kAhead / 2 < n_) {
      const std::uint32_t j = ids_[p + kAhead / 2];
      const std::uint64_t b = off[j], e = off[j + 1];
      if (e > b) {
        __builtin_prefetch(idx + b, 1);
        __builtin_prefetch(idx + e - 1, 1);
      }
    }
  }

  // Memory that is never zero filled (every entry is written before it is read), backed by 2 MiB
  // pages where Linux grants them: fresh 4 KiB pages cost a page fault each (on this project's VM
  // 32 MB of them took 80 ms, more than the rest of a build at 10^6).
  class WorkBuffer {
   public:
    void reserve(std::size_t n) {
      if (n <= size_) return;
      data_.reset();  // never hold the old and the new buffer at once
      data_.reset(new std::uint64_t[n]);
      size_ = n;
      advise_huge_pages(data_.get(), n * sizeof(std::uint64_t));
    }
    [[nodiscard]] std::uint64_t* data() const { return data_.get(); }
    [[nodiscard]] std::size_t size() const { return size_; }

   private:
    std::unique_ptr<std::uint64_t[]> data_;
    std::size_t size_ = 0;
  };

  // Particles [begin, end) in key order that lie in one mask cell (or several adjacent ones).
  struct Range {
    std::uint32_t begin, end;
    int gap2;
  };

  struct Bounds {
    Point lo, hi;
    Real hmin, hmax;
  };

  void clear() {
    n_ = 0;
    cells_.clear();
    cell_start_.clear();
    xs_.clear();
    hs_.clear();
    zero_cell_.clear();
    ids_.clear();
    wide_ = force_wide_;
    index_bits_ = cell_bits_ = 0;
  }

  static Bounds bounds(std::span<const Point> x, std::span<const Real> h, Real radius) {
    const Real h0 = h.empty() ? radius : h[0];
    Bounds all{x[0], x[0], h0, h0};
    bool finite = true;
#pragma omp parallel
    {
      Bounds loc = all;
      bool ok = true;
#pragma omp for schedule(static) nowait
      for (std::int64_t i = 0; i < static_cast<std::int64_t>(x.size()); ++i) {
        const auto& p = x[static_cast<std::size_t>(i)];
        const Real hi = h.empty() ? radius : h[static_cast<std::size_t>(i)];
        for (int k = 0; k < Dim; ++k) {
          ok = ok && std::isfinite(p[k]);
          loc.lo[k] = std::min(loc.lo[k], p[k]);
          loc.hi[k] = std::max(loc.hi[k], p[k]);
        }
        ok = ok && std::isfinite(hi) && hi >= Real(0);
        loc.hmin = std::min(loc.hmin, hi);
        loc.hmax = std::max(loc.hmax, hi);
      }
#pragma omp critical(cellsph_cell_index_bounds)
      {
        finite = finite && ok;
        for (int k = 0; k < Dim; ++k) {
          all.lo[k] = std::min(all.lo[k], loc.lo[k]);
          all.hi[k] = std::max(all.hi[k], loc.hi[k]);
        }
        all.hmin = std::min(all.hmin, loc.hmin);
        all.hmax = std::max(all.hmax, loc.hmax);
      }
    }
    CELLSPH_CHECK(finite, "cell-index: non-finite coordinate or support length, or negative support length");
    return all;
  }

  // The cell size h' = (max h / H) * inflation (section 4.1) and the H-mask for it; returns the mask's
  // reach in cells (the padding of the cell coordinates). Any positive size is exact when all h are 0.
  // The size is kept in [kMinCellSize, kMaxCellSize] (hmask.hpp says why). A support whose square
  // overflows Real makes every point its neighbour (distance2 <= inf): then one cell holds them all.
  int set_cells_and_mask(const Bounds& b) {
    cell_size_ = b.hmax > Real(0) ? double(b.hmax) / subdivision_ * kCellInflation : 1.0;
    cell_size_ = std::clamp(cell_size_, kMinCellSize<Real>, kMaxCellSize);
    one_cell_ = !std::isfinite(b.hmax * b.hmax);
    const double reach = one_cell_ ? 0.0 : double(b.hmax) / cell_size_;
    mask_ = h_mask<Dim>(reach);
    return mask_radius(reach);
  }

  // Stored coordinates are x - origin_ (in [0, extent]) rounded to float: within extent 2^-24 of it, or
  // float's subnormal spacing near 0 (band() uses twice both). Beyond 1e36 (float's range) the band is
  // infinite: every candidate is tested again in double.
  void set_float_band(const Bounds& b, std::span<const Point> x) {
    double extent = 0;
    for (int k = 0; k < Dim; ++k) extent = std::max(extent, double(b.hi[k]) - double(b.lo[k]));
    band_m_ =
        extent <= 1e36 ? 4 * std::max(extent * 0x1p-23, 0x1p-140) : std::numeric_limits<double>::infinity();
    band(hmax_, lo2_, hi2_);
    band(Real(0), lo2_zero_, hi2_zero_);
    xd_ = x.data();
  }

  // Bits per axis: cell coordinates are shifted by `pad` so that every mask target (home + offset) is
  // non-negative and below 2^bits on every axis; targets off the grid then simply find no cell. An axis
  // spanning more cells than fit (2^32 per axis, 64 bits in all) is cut: its last cell takes every farther
  // point (cell_key clamps). Clamping never moves two points' cells further apart, so every pair within h
  // stays within mask reach: exact for any finite input, and only slower for such extreme spreads (one far
  // outlier costs nothing: it is alone in its cell). Then each mask cell's key offset.
  void set_key_layout(const Bounds& b, int pad) {
    const auto pad2 = 2 * static_cast<std::uint64_t>(pad);
    std::array<int, Dim> bits{};
    for (int k = 0; k < Dim; ++k) {
      const double cells = std::floor((double(b.hi[k]) - origin_[k]) / cell_size_) + 1.0;
      const double most = 4294967296.0 - double(pad2);  // top = cells - 1 + 2 pad < 2^32
      axis_cells_[k] = one_cell_      ? 1
                       : cells < most ? static_cast<std::uint64_t>(cells)
                                      : static_cast<std::uint64_t>(most);
      bits[k] = static_cast<int>(std::bit_width(axis_cells_[k] - 1 + pad2));
    }
    auto total_bits = [&] {
      int t = 0;
      for (int k = 0; k < Dim; ++k) t += bits[k];
      return t;
    };
    while (total_bits() > 64) {
      const int k = static_cast<int>(std::max_element(bits.begin(), bits.end()) - bits.begin());
      --bits[k];  // top = 2^bits - 1
      axis_cells_[k] = (std::uint64_t{1} << bits[k]) - pad2;
    }
    int cell_bits = 0;
    for (int k = 0; k < Dim; ++k) {
      shift_[k] = cell_bits;
      cell_bits += bits[k];
    }
    cell_bits_ = cell_bits;
    index_bits_ = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(n_)));  // 2^I > N (eq. 17)
    wide_ = force_wide_ || index_bits_ + cell_bits > 64;
    deltas_.resize(mask_.size());
    for (std::size_t m = 0; m < mask_.size(); ++m) {
      std::uint64_t d = 0;  // two's complement wrap: home + d is exact for in-range targets
      for (int k = 0; k < Dim; ++k)
        d += static_cast<std::uint64_t>(static_cast<std::int64_t>(mask_[m].offset[k])) << shift_[k];
      deltas_[m] = d;
    }
  }

  std::uint64_t cell_key(const Point& p, int pad) const {
    std::uint64_t key = 0;
    for (int k = 0; k < Dim; ++k) {
      // p >= origin, so c >= 0 (+inf when the offset overflows): clamped to the axis' last cell.
      const double c = std::floor((double(p[k]) - origin_[k]) / cell_size_);
      const std::uint64_t last = axis_cells_[k] - 1;
      const std::uint64_t ck = c < double(last) ? static_cast<std::uint64_t>(c) : last;
      key |= (ck + static_cast<std::uint64_t>(pad)) << shift_[k];
    }
    return key;
  }

  // Sorts the particles by cell and fills ids_ (key order -> particle) and the list of non-empty
  // cells with their first particle.
  void sort_particles(std::span<const Point> x, int pad) {
    const std::size_t n = n_;
    // work_ holds the keys and the sort's second buffer here, and find_all's kept hit masks later.
    // It is kept from one build to the next (a solver rebuilds every step or few): fresh buffers
    // cost a page fault per 4 KiB and a zero fill each time, 45 ms of a 60 ms build at 10^6 here.
    work_.reserve(kStoreWords * n);
    std::uint64_t* keys = work_.data();
    std::vector<std::uint64_t> wide_keys, scratch;  // the wide path only
    // kPad spare entries, as for the positions: BlockBuffer copies ids in whole groups too.
    ids_.resize(n + kPad);
    std::fill(ids_.begin() + static_cast<std::ptrdiff_t>(n), ids_.end(), 0u);
    if (!wide_) {
      const int I = index_bits_;
      parallel_for(n, [&](std::size_t i) { keys[i] = (cell_key(x[i], pad) << I) | i; });
      // The index bits are already in order (keys are made in index order) and LSD passes are
      // stable, so sorting the cell bits alone gives the full eq. 17 order.
      keys = radix_sort(std::span(work_.data(), n), std::span(work_.data() + n, n), I, I + cell_bits_);
      const std::uint64_t low = (std::uint64_t{1} << I) - 1;
      parallel_for(n, [&](std::size_t p) { ids_[p] = static_cast<std::uint32_t>(keys[p] & low); });
      parallel_for(n, [&](std::size_t p) { keys[p] >>= I; });
    } else {
      std::vector<std::uint32_t> payload(n), payload_scratch;
      wide_keys.resize(n);
      parallel_for(n, [&](std::size_t i) {
        wide_keys[i] = cell_key(x[i], pad);
        payload[i] = static_cast<std::uint32_t>(i);
      });
      radix_sort_pairs(wide_keys, payload, scratch, payload_scratch, 0, cell_bits_);
      parallel_for(n, [&](std::size_t p) { ids_[p] = payload[p]; });
      keys = wide_keys.data();
    }
    // keys now holds each particle's cell key in sorted order: extract the distinct cells.
    const int max_t = max_threads();
    std::vector<std::size_t> starts(static_cast<std::size_t>(max_t) + 1, 0);
    int used_t = 1;
#pragma omp parallel
    {
      const auto nt = static_cast<std::size_t>(omp_get_num_threads());
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      const std::size_t b = n * t / nt, e = n * (t + 1) / nt;
      std::size_t c = 0;
      for (std::size_t p = b; p < e; ++p) c += (p == 0 || keys[p] != keys[p - 1]);
      starts[t + 1] = c;
#pragma omp barrier
#pragma omp single
      {
        used_t = static_cast<int>(nt);
        for (std::size_t s = 0; s < nt; ++s) starts[s + 1] += starts[s];
        cells_.resize(starts[nt] + 1);
        cell_start_.resize(starts[nt] + 1);
      }
      std::size_t u = starts[t];
      for (std::size_t p = b; p < e; ++p)
        if (p == 0 || keys[p] != keys[p - 1]) {
          cells_[u] = keys[p];
          cell_start_[u] = static_cast<std::uint32_t>(p);
          ++u;
        }
    }
    const std::size_t nc = starts[static_cast<std::size_t>(used_t)];
    cells_[nc] = std::numeric_limits<std::uint64_t>::max();  // sentinel: stops every cursor
    cell_start_[nc] = static_cast<std::uint32_t>(n);
  }

  // Positions and support lengths copied into key order: a cell's particles, and the cells along
  // axis 0, are then contiguous in memory.
  void gather(std::span<const Point> x, std::span<const Real> h) {
    // kPad spare entries: BlockBuffer copies whole groups of kPad past the end of a range.
    // Every entry below n_ is written next: only the padding needs a value.
    const std::size_t stride = n_ + kPad;
    if (xs_.capacity() < Dim * stride) {
      xs_.clear();
      xs_.shrink_to_fit();  // a larger set: never hold the old and the new copy at once
    }
    xs_.resize(Dim * stride);
    for (int k = 0; k < Dim; ++k) std::fill(xs(k) + n_, xs(k) + stride, 0.0f);
    // One support for all (the usual case) needs no array: hmax_ is every particle's.
    if (uniform_h_) {
      hs_.clear();
      hs_.shrink_to_fit();
    } else {
      hs_.resize(n_);
    }
    parallel_for(n_, [&](std::size_t p) {
      // Reads in key order from particle order: a miss each unless asked for ahead.
      if (p + kAhead < n_) __builtin_prefetch(&x[ids_[p + kAhead]]);
      const std::uint32_t i = ids_[p];
      for (int k = 0; k < Dim; ++k) {
        if constexpr (kBand) {
          const double c = std::min(double(x[i][k]) - origin_[k], 1e36);  // beyond it band_m_ is infinite
          xs(k)[p] = static_cast<float>(c);
        } else {
          xs(k)[p] = x[i][k];
        }
      }
      if (!uniform_h_) hs_[p] = h[i];
    });
    // Cells whose particles all have support 0 (the solver's wall particles, which need no rows).
    const std::size_t nc = cell_count();
    if (uniform_h_) {
      zero_cell_.assign(nc, hmax_ == 0 ? 1 : 0);
      return;
    }
    zero_cell_.assign(nc, 0);
    parallel_for(nc, [&](std::size_t u) {
      bool zero = true;
      for (std::uint32_t p = cell_start_[u]; p < cell_start_[u + 1]; ++p) zero = zero && hs_[p] == 0;
      zero_cell_[u] = zero ? 1 : 0;
    });
  }

  static std::uint64_t popcount64(std::uint64_t v) {
    // SWAR popcount: portable and branch free without -mpopcnt (std::popcount becomes a libgcc call).
    v = v - ((v >> 1) & 0x5555555555555555ull);
    v = (v & 0x3333333333333333ull) + ((v >> 2) & 0x3333333333333333ull);
    v = (v + (v >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return (v * 0x0101010101010101ull) >> 56;
  }

  // Sorts the distinct values in[0, L) (L <= kRankSortMax) into out: rows of up to 64 with a sorting
  // network where AVX2 is, others by rank. in must have room for kRankSortMax + 8 entries.
  void sort_row(std::uint32_t* in, std::uint32_t L, std::uint32_t* out) const {
#if defined(CELLSPH_CELL_INDEX_X86)
    if (simd_ == SimdPath::Avx2 && L <= 64) {
      if (L > 0) detail::sort_row_avx2(in, L, out);
      return;
    }
#endif
    rank_sort(in, L, out);
  }

  // Sorts the distinct values in[0, L) into out by rank: out[#{m : in[m] < in[k]}] = in[k]. No
  // data-dependent branches, unlike insertion sort on rows that arrive in cell order. in must have
  // room for 8 entries past L (overwritten).
  void rank_sort(std::uint32_t* in, std::uint32_t L, std::uint32_t* out) const {
    for (std::uint32_t t = L; t < L + 8; ++t) in[t] = std::numeric_limits<std::uint32_t>::max();
#if defined(CELLSPH_CELL_INDEX_X86)
    if (simd_ == SimdPath::Avx2) return detail::rank_sort_avx2<kRankSortMax>(in, L, out);
    if (simd_ == SimdPath::Sse2) return detail::rank_sort_sse2(in, L, out);
#endif
    detail::rank_sort_scalar(in, L, out);
  }

  // A particle's candidates copied side by side, so that the distance loop runs over one
  // contiguous block instead of a few short ranges; padded by kPad.
  struct Block {
    const float* x[Dim];
    const std::uint32_t* id;  // particle indices (only when has_ids)
    const Range* r;           // the ranges the block was filled from, in order (key_index)
    bool has_ids;
    std::uint32_t* scratch;  // room for n + kPad entries: the fill pass gathers long rows there
    std::uint32_t n;
    // The home cell's particles are consecutive in the block: key-order particle p sits at
    // candidate self0 + (p - p0), unless the block was sorted by particle index (by_id), which
    // moves them to self_pos[p - p0].
    std::uint32_t self0, p0;
    const std::uint32_t* self_pos;
    bool by_id;
    [[nodiscard]] std::uint32_t self(std::uint32_t p) const {
      return by_id ? self_pos[p - p0] : self0 + (p - p0);
    }
    // The key-order particle at candidate t of a block in range order (not by_id).
    [[nodiscard]] std::uint32_t key_index(std::uint32_t t) const {
      for (const Range* s = r;; ++s) {
        const std::uint32_t len = s->end - s->begin;
        if (t < len) return s->begin + t;
        t -= len;
      }
    }
  };

  // One particle's query: its stored position and the bounds of hits64.
  struct Probe {
    float x[Dim];
    float h2;         // float search: h^2; double search: the bound above which no candidate is a neighbour
    float lo2;        // double search: the bound at or below which every candidate is one
    Real h2r;         // double search: h^2, the exact test of the candidates in between
    std::uint32_t i;  // double search: the particle (its caller's position)
  };

  Probe probe(std::uint32_t p) const {
    Probe pr{};
    for (int k = 0; k < Dim; ++k) pr.x[k] = xs(k)[p];
    const Real hp = uniform_h_ ? hmax_ : hs_[p];
    pr.h2r = hp * hp;
    if constexpr (kBand) {
      pr.i = ids_[p];
      // The solver's supports are hmax_ (fluid) and 0 (walls): their bounds are computed once.
      if (hp == hmax_) {
        pr.lo2 = lo2_;
        pr.h2 = hi2_;
      } else if (hp == 0) {
        pr.lo2 = lo2_zero_;
        pr.h2 = hi2_zero_;
      } else {
        band(hp, pr.lo2, pr.h2);
      }
    } else {
      pr.h2 = pr.h2r;  // lo2 is not read: float_hits<false>
    }
    return pr;
  }

  // Position in a block filled from ranges r[0, nr) of key-order particle q (which they hold).
  static std::uint32_t block_pos(const Range* r, int nr, std::uint32_t q) {
    std::uint32_t o = 0;
    for (int s = 0; s < nr; ++s) {
      if (r[s].begin <= q && q < r[s].end) return o + (q - r[s].begin);
      o += r[s].end - r[s].begin;
    }
    return o;  // not reached: the home cell is always among the ranges (its gap is 0)
  }

  struct BlockBuffer {
    std::array<std::vector<float>, Dim> x, x_sorted;
    std::vector<std::uint32_t> id, self_pos, scratch;
    std::vector<std::uint64_t> order, order2;

    // Reorders a filled block by particle index, so that every row found in it is ascending
    // without a sort of its own: one sort per home cell instead of one per particle, which pays
    // in dense cells (hundreds of particles) whose rows are long. `home` particles of the home
    // cell start at blk.self0. An LSD radix sort of the ids, 8 bits a pass over the bits in
    // which they differ (ids are distinct, so the order is total). Positions move only with_x.
    void sort_by_id(Block& blk, std::uint32_t home, bool with_x) {
      const std::uint32_t n = blk.n;
      std::uint32_t lo = id[0], hi = id[0];
      for (std::uint32_t t = 1; t < n; ++t) {
        lo = std::min(lo, id[t]);
        hi = std::max(hi, id[t]);
      }
      order.resize(n);
      order2.resize(n);
      for (std::uint32_t t = 0; t < n; ++t) order[t] = (std::uint64_t{id[t] - lo} << 32) | t;
      const int bits = static_cast<int>(std::bit_width(hi - lo));
      for (int shift = 32; shift < 32 + bits; shift += 8) {
        std::uint32_t count[257] = {};
        for (std::uint32_t t = 0; t < n; ++t) ++count[((order[t] >> shift) & 0xFFu) + 1];
        for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
        for (std::uint32_t t = 0; t < n; ++t) order2[count[(order[t] >> shift) & 0xFFu]++] = order[t];
        order.swap(order2);
      }
      self_pos.resize(home);
      for (int k = 0; k < Dim && with_x; ++k) x_sorted[k].resize(x[k].size());
      for (std::uint32_t t = 0; t < n; ++t) {
        const auto from = static_cast<std::uint32_t>(order[t]);
        for (int k = 0; k < Dim && with_x; ++k) x_sorted[k][t] = x[k][from];
        id[t] = static_cast<std::uint32_t>(order[t] >> 32) + lo;
        if (from - blk.self0 < home) self_pos[from - blk.self0] = t;
      }
      for (int k = 0; k < Dim && with_x; ++k) {
        std::swap(x[k], x_sorted[k]);
        blk.x[k] = x[k].data();
      }
      blk.self_pos = self_pos.data();
      blk.by_id = true;
    }

    // After sort_by_id: where each of the block's n candidates came from, 16 bits each (four a
    // word), to dst.
    void save_order(std::uint64_t* dst, std::uint32_t n) const {
      for (std::uint32_t t = 0; t < n; t += 4) {
        std::uint64_t w = 0;
        for (std::uint32_t k = 0; k < 4 && t + k < n; ++k) w |= (order[t + k] & 0xFFFFu) << (16 * k);
        dst[t / 4] = w;
      }
    }

    // Puts a freshly filled block's ids in the order save_order kept (the fill pass: no positions).
    void permute_ids(Block& blk, const std::uint64_t* src) {
      for (std::uint32_t t = 0; t < blk.n; ++t) scratch[t] = id[(src[t / 4] >> (16 * (t % 4))) & 0xFFFFu];
      std::swap(id, scratch);
      blk.id = id.data();
      blk.scratch = scratch.data();
      blk.by_id = true;
    }

    // Copies the particles of ranges r[0, nr) (total of them) into the buffer: their positions
    // (with_x; a block whose hit masks were kept needs none) and their ids (with_ids).
    Block fill(const CellIndex& ci, const Range* r, int nr, std::uint32_t total, bool with_x, bool with_ids) {
      if (id.size() < total + kPad) {
        for (auto& v : x) v.resize(total + kPad, 0.0f);
        id.resize(total + kPad, 0);
        scratch.resize(total + kPad);
      }
      std::uint32_t o = 0;
      for (int s = 0; s < nr; ++s) {
        const std::uint32_t b = r[s].begin, len = r[s].end - r[s].begin;
        // Whole groups of kPad: fixed-size copies the compiler inlines (ranges are ~10-30 long,
        // too short for a memmove call to pay); the overshoot lands in padding.
        for (int k = 0; k < Dim && with_x; ++k) {
          const float* src = ci.xs(k) + b;
          float* dst = x[k].data() + o;
          for (std::uint32_t t = 0; t < len; t += kPad) std::memcpy(dst + t, src + t, kPad * sizeof(float));
        }
        if (with_ids) {
          const std::uint32_t* src = ci.ids_.data() + b;
          std::uint32_t* dst = id.data() + o;
          for (std::uint32_t t = 0; t < len; t += kPad)
            std::memcpy(dst + t, src + t, kPad * sizeof(std::uint32_t));
        }
        o += len;
      }
      Block blk{};
      for (int k = 0; k < Dim; ++k) blk.x[k] = x[k].data();
      blk.id = id.data();
      blk.r = r;
      blk.has_ids = with_ids;
      blk.scratch = scratch.data();
      blk.n = total;
      return blk;
    }
  };

  // distance2 order again, on the block's copy of the positions (float searches only).
  static float block_dist2(const Block& blk, const float* xi, std::uint32_t t) {
    float d = xi[0] - blk.x[0][t];
    float s = d * d;
    for (int k = 1; k < Dim; ++k) {
      d = xi[k] - blk.x[k][t];
      s += d * d;
    }
    return s;
  }

  // The hit mask of candidates [b, b + 64) of p's block without p itself.
  std::uint64_t hits_but_self(std::uint32_t p, const Block& blk, const Probe& pr, std::uint32_t b) const {
    const std::uint32_t s = blk.self(p) - b;  // wraps to a large value when self < b
    const std::uint64_t self = s < 64 ? std::uint64_t{1} << s : 0;
    return hits64(blk, pr, b, std::min<std::uint32_t>(64, blk.n - b), self) & ~self;
  }

  // Calls g(t, j) for every candidate t of the block, particle j != p, with distance2 <= h_p^2
  // (pr: probe(p)).
  template <class G>
  void for_each_hit(std::uint32_t p, const Block& blk, const Probe& pr, G&& g) const {
    for (std::uint32_t b = 0; b < blk.n; b += 64) {
      // About 1 candidate in 7 is a neighbour: iterating the set bits of a hit mask costs one
      // step per neighbour and no branch per candidate.
      std::uint64_t bits = hits_but_self(p, blk, pr, b);
      while (bits != 0) {
        const std::uint32_t t = b + static_cast<std::uint32_t>(std::countr_zero(bits));
        bits &= bits - 1;
        g(t, blk.id[t]);
      }
    }
  }

  // Writes the candidates whose bits are set in the stored masks bits[] (one word per 64 of the
  // block's candidates) to dst in block order; returns how many. dst needs 8 spare entries.
  std::uint32_t pack_hits(const std::uint64_t* bits, const Block& blk, std::uint32_t* dst) const {
    std::uint32_t c = 0;
    for (std::uint32_t b = 0, w = 0; b < blk.n; b += 64, ++w) {
#if defined(CELLSPH_CELL_INDEX_X86)
      if (simd_ == SimdPath::Avx2) {
        c += detail::left_pack_avx2(blk.id + b, bits[w], std::min<std::uint32_t>(64, blk.n - b), dst + c);
        continue;
      }
#endif
      for (std::uint64_t m = bits[w]; m != 0; m &= m - 1)
        dst[c++] = blk.id[b + static_cast<std::uint32_t>(std::countr_zero(m))];
    }
    return c;
  }

  // Bit t set when candidate b + t (t < m <= 64) is a neighbour: distance2(x_i, x_{b+t}) <= h_i^2
  // in Real, exactly as the all-pairs reference decides it. Reads up to kPad entries past b + m
  // (padding). Float searches test the block's float positions, 8 (AVX2) or 4 (SSE2) at a time with
  // the same operations in the same order as distance2, so bit-identically. Double searches test the
  // same float copies (relative to the origin: see xs_) against two bounds, lo2 <= hi2, that bracket
  // h_i^2 by more than float's error in the positions and the arithmetic: a candidate at or below lo2
  // is a neighbour and one above hi2 is not; the few in between are tested again in double, from the
  // caller's positions, with distance2 itself.
  // Bits in `skip` (p itself, which the caller drops) are not tested again in double.
  std::uint64_t hits64(const Block& blk, const Probe& pr, std::uint32_t b, std::uint32_t m,
                       std::uint64_t skip = 0) const {
    const float* ax[Dim];
    for (int k = 0; k < Dim; ++k) ax[k] = blk.x[k] + b;
    std::uint64_t sure = 0;
    const std::uint64_t maybe = float_hits<kBand>(ax, pr.x, pr.lo2, pr.h2, m, &sure);
    if constexpr (!kBand) {
      return maybe;
    } else {
      const std::uint64_t open = maybe & ~sure & ~skip;
      return open == 0 ? sure : sure | retest(blk, pr, b, open);
    }
  }

  // hits64's exact test in double of the candidates b + t, t in `open`: the bits of the neighbours.
  // Out of line: most calls have none, and inlined it crowds the float loop's registers.
  [[gnu::noinline]] std::uint64_t retest(const Block& blk, const Probe& pr, std::uint32_t b,
                                         std::uint64_t open) const {
    std::uint64_t in = 0;
    const Point& xi = xd_[pr.i];
    for (; open != 0; open &= open - 1) {
      const auto t = static_cast<std::uint32_t>(std::countr_zero(open));
      const std::uint32_t j = blk.has_ids ? blk.id[b + t] : ids_[blk.key_index(b + t)];
      // No branch: a lattice's pairs at exactly h (a scene's start) are in or out at random.
      in |= static_cast<std::uint64_t>(distance2(xi, xd_[j]) <= pr.h2r) << t;
    }
    return in;
  }

  // hits64's float test: bits with d2 <= hi2, and with Band *sure gets those with d2 <= lo2.
  template <bool Band>
  std::uint64_t float_hits(const float* const* ax, const float* xi, float lo2, float hi2, std::uint32_t m,
                           std::uint64_t* sure) const {
#if defined(CELLSPH_CELL_INDEX_X86)
    if (simd_ == SimdPath::Avx2) return detail::hits64_avx2<Dim, Band>(ax, xi, lo2, hi2, m, sure);
    if (simd_ == SimdPath::Sse2) return detail::hits64_sse2<Dim, Band>(ax, xi, lo2, hi2, m, sure);
#endif
    return detail::hits64_scalar<Dim, Band>(ax, xi, lo2, hi2, m, sure);
  }

  // Float bounds around h^2 for a double search (hits64): a float distance2 at or below lo2 is
  // certainly within h, one above hi2 certainly not. Each stored coordinate is within e = band_m_ / 4
  // of x - origin, so a float distance is within 2 sqrt(Dim) e <= band_m_ of the true one, and its
  // square carries at most (Dim + 3) rounding errors of 2^-24 (bounded by 2^-21 here); 2^-50 h more
  // covers distance2's own rounding in double. Squares below 1e-30, where float's subnormals lose
  // relative precision, are never sure. An infinite band_m_ gives lo2 = -1 and hi2 = +inf: every
  // candidate a re-test.
  void band(Real hp, float& lo2, float& hi2) const {
    constexpr double c = 0x1p-21, s = 0x1p-50, tiny = 1e-30;
    const double h = double(hp);
    const double l = h * (1 - s) - band_m_, u = h * (1 + s) + band_m_;
    const double lo = l > 0 ? l * l * (1 - c) : -1.0;
    lo2 = lo >= tiny ? float_below(lo) : -1.0f;
    hi2 = float_above(std::max(u * u * (1 + c), tiny));
  }
  // A float at most v (v >= 1e-30, so normal: rounding to nearest is within 2^-24 of v); +inf stays.
  static float float_below(double v) {
    v *= 1 - 0x1p-22;
    if (v > double(std::numeric_limits<float>::max()))
      return v == std::numeric_limits<double>::infinity() ? std::numeric_limits<float>::infinity()
                                                          : std::numeric_limits<float>::max();
    return static_cast<float>(v);
  }
  // A float at least v (v >= 1e-30).
  static float float_above(double v) {
    v *= 1 + 0x1p-22;
    return v > double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::infinity()
                                                         : static_cast<float>(v);
  }

  // Where find_all's count pass keeps the hit masks and its fill pass finds them (traverse).
  enum class Masks { None, Write, Read };

  // The hit masks of one chunk's particles whose blocks exceed kStoreMax candidates, and the sort
  // order of its blocks sorted by id (BlockBuffer::save_order), in traversal order: the count pass
  // appends them, the fill pass takes them back in the same order (so it sorts no block again, up
  // to kept_order_max_ candidates; memory for speed: see docs/benchmarks.md). Stored in pages of at least
  // kSpillPage words, so that at most the tail of each page is unused (a doubling vector would
  // hold up to twice what it needs); a take that does not fit the rest of a page starts the next
  // one, enlarged first if the take is larger. The count pass only ever enlarges a page before
  // its first take, so the fill pass, taking the same sizes in the same order, finds the same
  // places. Pages are kept from one find_all to the next, never zero filled.
  struct Spill {
    struct Page {
      std::unique_ptr<std::uint64_t[]> words;
      std::size_t size = 0;
    };
    std::vector<Page> pages;
    std::size_t page = 0, at = 0;
    void rewind() { page = at = 0; }
    template <bool Append>
    std::uint64_t* take(std::size_t w) {
      if (pages.empty() || at + w > pages[page].size) {
        if (!pages.empty()) ++page;
        at = 0;
        if constexpr (Append) {
          if (page == pages.size()) pages.emplace_back();
          Page& pg = pages[page];
          if (pg.size < w) {
            pg.words.reset();
            pg.size = std::max(w, kSpillPage);
            pg.words.reset(new std::uint64_t[pg.size]);
          }
        }
      }
      std::uint64_t* p = pages[page].words.get() + at;
      at += w;
      return p;
    }
    [[nodiscard]] std::size_t bytes() const {
      std::size_t b = 0;
      for (const auto& pg : pages) b += pg.size * sizeof(std::uint64_t);
      return b;
    }
  };

  // The streaming traversal of section 4.2. The sorted cells are split into chunks with
  // boundaries that depend only on the data; each chunk places its cursors by binary search at its
  // first cell, then moves them forward only. kernel(p, block, masks) is called once per particle p
  // (key order) with the candidates its own support needs. Returns the distance tests.
  // ById: blocks of at least kSortBlockMin candidates shared by a whole home cell are sorted by
  // particle index (BlockBuffer::sort_by_id), for rows that must come out ascending.
  // Kept: masks is where p's hit masks go (Write: ceil(n / 64) words) or are (Read); null with None.
  // Blocks of at most kStoreMax candidates keep them in work_ (kStoreWords words a particle),
  // longer ones in their chunk's spill. A Read traversal copies no positions.
  // The steps of a home cell are named below (visit_zero_cell, find_mask_cells, gather_home, own_support),
  // always inlined, with the chunk's state passed as locals: kept in a struct instead, the search was 40%
  // slower at subdivision 2 (BM_CellIndexBuildAndLists/H:2).
  template <bool WithIds, bool ById = false, Masks Kept = Masks::None, class Kernel>
  std::uint64_t traverse(Kernel&& kernel) const {
    const std::size_t nc = cell_count();
    if (nc == 0) return 0;
    const std::size_t M = mask_.size();
    // About 4096 particles per chunk.
    const std::size_t grain = std::max<std::size_t>(1, nc * 4096 / n_);
    if constexpr (Kept == Masks::Write) spill_.resize((nc + grain - 1) / grain);
    const std::uint64_t* cells = cells_.data();
    const std::uint32_t* start = cell_start_.data();
    constexpr bool with_x = Kept != Masks::Read;
    std::atomic<std::uint64_t> tests{0};
    parallel_chunks(nc, grain, [&](std::size_t u0, std::size_t u1) {
      Spill* spill = Kept == Masks::None ? nullptr : &spill_[u0 / grain];
      if (spill != nullptr) spill->rewind();
      // p's masks for a block of n candidates.
      auto masks = [&](std::uint32_t p, std::uint32_t n) -> std::uint64_t* {
        if constexpr (Kept == Masks::None) {
          return nullptr;
        } else {
          if (n <= kStoreMax) return work_.data() + std::size_t{p} * kStoreWords;
          return spill->template take<Kept == Masks::Write>((n + 63) / 64);
        }
      };
      std::vector<std::uint32_t> cur(M);
      std::vector<Range> found(M), merged(M), mine(M);
      BlockBuffer home_buf, own_buf;
      for (std::size_t m = 0; m < M; ++m)
        cur[m] =
            static_cast<std::uint32_t>(std::lower_bound(cells, cells + nc, cells[u0] + deltas_[m]) - cells);
      std::uint64_t local_tests = 0;
      for (std::size_t u = u0; u < u1; ++u) {
        if (zero_cell_[u]) {
          local_tests += visit_zero_cell<WithIds, with_x>(u, kernel, masks, own_buf);
          continue;  // the cursors catch up at the next cell
        }
        const int nf = find_mask_cells(cells[u], cur.data(), found.data());
        // Mask cells found in consecutive sorted cells (neighbours along axis 0) are one range.
        const int nm = merge(found.data(), nf, merged.data());
        std::uint32_t total = 0;
        for (int s = 0; s < nm; ++s)
          total += merged[static_cast<std::size_t>(s)].end - merged[static_cast<std::size_t>(s)].begin;
        bool gathered = false;
        Block home_blk{};
        for (std::uint32_t p = start[u]; p < start[u + 1]; ++p) {
          if (uniform_h_ || hs_[p] == hmax_) {
            // Full support: the whole mask, shared by every such particle of the home cell.
            if (!gathered)
              home_blk =
                  gather_home<WithIds, ById, Kept, with_x>(u, merged.data(), nm, total, home_buf, spill);
            gathered = true;
            local_tests += total - 1;
            kernel(p, home_blk, masks(p, total));
          } else if (!zero_rows_ && hs_[p] == 0) {
            kernel(p, Block{}, masks(p, 0));  // an empty row, not searched (zero_support_rows)
          } else {
            local_tests +=
                own_support<WithIds, with_x>(p, u, found.data(), nf, mine.data(), own_buf, kernel, masks);
          }
        }
      }
      tests.fetch_add(local_tests, std::memory_order_relaxed);
    });
    return tests.load();
  }

  // Home cell u of traverse whose particles all have support 0; returns the distance tests. Without
  // zero_rows_ each gets an empty row; with them its neighbours are the points at distance 0, which share
  // the home cell (a cell is a function of the position).
  template <bool WithIds, bool WithX, class Kernel, class MaskFn>
  [[gnu::always_inline]] std::uint64_t visit_zero_cell(std::size_t u, Kernel& kernel, MaskFn& masks,
                                                       BlockBuffer& buf) const {
    const std::uint32_t* start = cell_start_.data();
    if (!zero_rows_) {
      for (std::uint32_t p = start[u]; p < start[u + 1]; ++p) kernel(p, Block{}, masks(p, 0));
      return 0;
    }
    const Range home_only{start[u], start[u + 1], 0};
    const std::uint32_t len = home_only.end - home_only.begin;
    std::uint64_t tests = 0;
    for (std::uint32_t p = start[u]; p < start[u + 1]; ++p) {
      tests += len - 1;
      Block blk = buf.fill(*this, &home_only, 1, len, WithX, WithIds);
      blk.self0 = 0;
      blk.p0 = start[u];
      kernel(p, blk, masks(p, len));
    }
    return tests;
  }

  // Moves traverse's cursors `cur` (one per mask cell) to the mask cells of home cell `home` and puts the
  // occupied ones in `found`; returns how many there are.
  [[gnu::always_inline]] int find_mask_cells(std::uint64_t home, std::uint32_t* cur, Range* found) const {
    const std::uint64_t* cells = cells_.data();
    const std::uint32_t* start = cell_start_.data();
    const std::size_t nc = cell_count(), M = mask_.size();
    int nf = 0;
    for (std::size_t m = 0; m < M; ++m) {
      const std::uint64_t t = home + deltas_[m];
      std::uint32_t c = cur[m];
      // A cursor mostly moves 0 or 1 cell per home cell: two branch-free steps, then a loop
      // that runs only after a gap in the occupied cells.
      c += cells[c] < t ? 1u : 0u;
      c += cells[c] < t ? 1u : 0u;
      while (cells[c] < t) ++c;
      cur[m] = c;
      // Visit only an exact match; the sentinel (c == nc) never is one. Written branch free.
      found[nf] = {start[c], start[c + (c < nc ? 1 : 0)], mask_[m].gap2};
      nf += (cells[c] == t && c < nc) ? 1 : 0;
    }
    return nf;
  }

  // The full support's block of home cell u: the nm ranges `merged`, `total` candidates. A block sorted by
  // id needs its ids, whether or not the kernel reads them. The fill pass gathers them again and takes back
  // from the count pass's spill where each came from (16 bits a candidate, so blocks up to 2^16), instead
  // of sorting again.
  template <bool WithIds, bool ById, Masks Kept, bool WithX>
  [[gnu::always_inline]] Block gather_home(std::size_t u, const Range* merged, int nm, std::uint32_t total,
                                           BlockBuffer& buf, Spill* spill) const {
    const std::uint32_t* start = cell_start_.data();
    const bool by_id = ById && total >= kSortBlockMin;
    const bool kept_order = by_id && total <= kept_order_max_;
    const std::size_t order_words = (std::size_t{total} + 3) / 4;
    Block blk = buf.fill(*this, merged, nm, total, WithX, WithIds || by_id);
    blk.self0 = block_pos(merged, nm, start[u]);
    blk.p0 = start[u];
    if (Kept == Masks::Read && kept_order) {
      buf.permute_ids(blk, spill->template take<false>(order_words));
    } else if (by_id) {
      buf.sort_by_id(blk, start[u + 1] - start[u], WithX);
      if (Kept == Masks::Write && kept_order) buf.save_order(spill->template take<true>(order_words), total);
    }
    return blk;
  }

  // Particle p of home cell u with a smaller support (section 4.1): only the nf mask cells `found` that can
  // reach within h_p, gathered into `mine`; returns the distance tests.
  template <bool WithIds, bool WithX, class Kernel, class MaskFn>
  [[gnu::always_inline]] std::uint64_t own_support(std::uint32_t p, std::size_t u, const Range* found, int nf,
                                                   Range* mine, BlockBuffer& buf, Kernel& kernel,
                                                   MaskFn& masks) const {
    const double reach = double(hs_[p]) / cell_size_;
    int nk = 0;
    std::uint32_t mt = 0;
    for (int s = 0; s < nf; ++s) {
      const Range& r = found[s];
      if (!mask_keeps(r.gap2, reach)) continue;
      if (nk > 0 && mine[nk - 1].end == r.begin)
        mine[nk - 1].end = r.end;
      else
        mine[nk++] = r;
      mt += r.end - r.begin;
    }
    Block blk = buf.fill(*this, mine, nk, mt, WithX, WithIds);
    blk.self0 = block_pos(mine, nk, cell_start_[u]);
    blk.p0 = cell_start_[u];
    kernel(p, blk, masks(p, mt));
    return std::uint64_t{mt - 1};
  }

  static int merge(const Range* in, int n, Range* out) {
    int k = 0;
    for (int s = 0; s < n; ++s) {
      if (k > 0 && out[k - 1].end == in[s].begin)
        out[k - 1].end = in[s].end;
      else
        out[k++] = in[s];
    }
    return k;
  }

  static constexpr std::size_t kPad = 8;
  static constexpr std::uint32_t kRankSortMax = 96;
  static constexpr std::uint32_t kSortBlockMin = 320;
  // Hit masks kept between the two passes of find_all in work_: blocks of up to kStoreMax
  // candidates (the 27 cells of a uniform set hold ~216), kStoreWords words a particle; longer
  // blocks' masks go to their chunk's spill.
  static constexpr std::uint32_t kStoreWords = 4, kStoreMax = 64 * kStoreWords;
  static constexpr std::size_t kSpillPage = std::size_t{1} << 11;  // 16 KiB
  static constexpr std::uint32_t kKeptOrderMax = std::uint32_t{1} << 16;

  int subdivision_ = 1;
  bool sorted_rows_ = true;
  bool zero_rows_ = true;        // SearchOptions::zero_support_rows
  SimdPath simd_ = simd_path();  // the width of the inner loops (cell_index_simd.hpp)
  bool force_wide_ = false;
  std::uint32_t kept_order_max_ = kKeptOrderMax;
  std::size_t n_ = 0;
  bool wide_ = false;
  bool one_cell_ = false;  // a support whose square overflows Real: one cell holds every point
  bool uniform_h_ = true;
  Real hmax_ = 0;
  double cell_size_ = 1.0;
  std::array<double, Dim> origin_{};
  std::array<int, Dim> shift_{};
  std::array<std::uint64_t, Dim> axis_cells_{};  // cells per axis (the last one takes every farther point)
  int index_bits_ = 0;
  int cell_bits_ = 0;
  std::vector<MaskCell<Dim>> mask_;
  std::vector<std::uint64_t> deltas_;      // key offset of each mask cell, mod 2^64
  std::vector<std::uint64_t> cells_;       // distinct cell keys in order, + UINT64_MAX sentinel
  std::vector<std::uint32_t> cell_start_;  // first particle (key order) of each cell, + n
  // Positions in key order, one array per axis, in float: a float search's own values; a double
  // search's x - origin_ rounded to float, half the bytes to hold and to copy into blocks and twice
  // the candidates per SIMD test, with an exact test in double left to the few near h (hits64).
  // One allocation (axis k at k (n + kPad)): large enough to be given 2 MiB pages.
  FreshVector<float> xs_;
  [[nodiscard]] float* xs(int k) {
    return xs_.data() + std::size_t(k) * (n_ + kPad);
  }
  [[nodiscard]] const float* xs(int k) const {
    return xs_.data() + std::size_t(k) * (n_ + kPad);
  }
  static constexpr bool kBand = !std::is_same_v<Real, float>;
  const Point* xd_ = nullptr;  // double search: the caller's positions (build's x)
  double band_m_ = 0;  // double search: 4 x a stored coordinate's largest error (band); inf: all re-tested
  float lo2_ = 0, hi2_ = 0;              // double search: band's bounds for hmax_
  float lo2_zero_ = 0, hi2_zero_ = 0;    // and for support 0
  std::vector<Real> hs_;                 // support lengths in key order (empty when all are hmax_)
  std::vector<std::uint8_t> zero_cell_;  // 1: every particle of the cell has support 0
  FreshVector<std::uint32_t> ids_;       // key order -> particle index
  // The sort's keys and second buffer in build, find_all's kept hit masks (kStoreWords words a
  // particle) after: kept from one build to the next.
  mutable WorkBuffer work_;
  mutable std::vector<Spill> spill_;  // one per traversal chunk: the masks of blocks over kStoreMax
};

}  // namespace cellsph
