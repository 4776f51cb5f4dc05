#pragma once
// Extended Spatial Hashing (paper section 4.1): particles are binned into cells of eq. 15 relative
// to the bounding box's minimal corner, the cells are hashed with Teschner's three primes into a
// table of M buckets, and each particle searches the cells of the H-mask around its own cell.
//
// Exactness: two different cells can share a bucket, and two cells of one particle's mask can hash
// to the same bucket. Each bucket entry therefore keeps its particle's cell coordinates, and a
// visit to mask cell c accepts only entries whose cell equals c: every candidate is tested once,
// in the one mask cell that really holds it, and no pair is reported twice or missed.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <sstream>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/hmask.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

// The virtual grid of eq. 15 shared by the grid-based methods: origin at the bounding box's minimal
// corner, cells of size h' = (max_i h_i / H) * kCellInflation. Cell coordinates are computed in
// double so that float input and large offsets cannot shift a point into the wrong cell by more
// than the margin hmask.hpp reserves.
template <int Dim, class Real>
struct CellFrame {
  using Cell = std::array<std::int32_t, Dim>;

  std::array<double, Dim> lo{};
  std::array<std::int64_t, Dim> dims{};  // cells per axis covering the bounding box
  double cell = 1.0;                     // h'
  double inv_cell = 1.0;
  double max_h = 0.0;

  // 2^30 cells per axis: cell coordinates plus mask offsets stay well inside int32.
  static constexpr double kMaxCellsPerAxis = 1073741824.0;
  bool one_cell = false;  // h^2 overflows Real: every point is in one cell (see build)

  // `what` names the method in error messages.
  void build(std::span<const Vec<Dim, Real>> x, std::span<const Real> h, int subdivision, const char* what) {
    CELLSPH_CHECK(subdivision >= 1, what << ": subdivision H must be >= 1, got " << subdivision);
    CELLSPH_CHECK(x.size() < std::numeric_limits<std::uint32_t>::max(),
                  what << ": " << x.size() << " points exceed 32-bit indices");
    std::array<double, Dim> hi{};
    lo.fill(0.0);
    hi.fill(0.0);
    max_h = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      CELLSPH_CHECK(all_finite(x[i]), what << ": point " << i << " has a non-finite coordinate");
      CELLSPH_CHECK(std::isfinite(h[i]) && h[i] >= Real(0),
                    what << ": support length h[" << i << "] = " << h[i] << " is not finite and >= 0");
      max_h = std::max(max_h, static_cast<double>(h[i]));
      for (int k = 0; k < Dim; ++k) {
        const double v = static_cast<double>(x[i][k]);
        if (i == 0 || v < lo[k]) lo[k] = v;
        if (i == 0 || v > hi[k]) hi[k] = v;
      }
    }
    double extent = 0.0;
    for (int k = 0; k < Dim; ++k) extent = std::max(extent, hi[k] - lo[k]);
    // With every h = 0 only exact duplicates are neighbours; any positive cell size is exact then.
    cell = max_h > 0.0 ? max_h / subdivision * kCellInflation : std::max(extent, 1.0);
    cell = std::clamp(cell, kMinCellSize<Real>, kMaxCellSize);  // see hmask.hpp
    inv_cell = 1.0 / cell;
    // A support whose square overflows Real makes every point a neighbour (distance2 <= inf): one
    // cell holds them all, and its own cell is the whole mask.
    one_cell = !std::isfinite(static_cast<Real>(max_h) * static_cast<Real>(max_h));
    if (one_cell) {
      dims.fill(1);
      return;
    }
    for (int k = 0; k < Dim; ++k) {
      // Beyond kMaxCellsPerAxis the last cell of the axis takes every farther point (cell_of clamps).
      // Clamping never moves two points' cells further apart, so every pair within h still lies in
      // mask reach of each other: exact for any finite input, only slower for such extreme spreads.
      const double d = std::floor((hi[k] - lo[k]) * inv_cell) + 1.0;
      dims[k] =
          d < kMaxCellsPerAxis ? static_cast<std::int64_t>(d) : static_cast<std::int64_t>(kMaxCellsPerAxis);
    }
  }

  // eq. 15: cell(x) = floor((x - c_min) / h').
  [[nodiscard]] Cell cell_of(const Vec<Dim, Real>& p) const {
    Cell c{};
    for (int k = 0; k < Dim; ++k) {
      const double v = std::floor((static_cast<double>(p[k]) - lo[k]) * inv_cell);
      c[k] = static_cast<std::int32_t>(std::clamp(v, 0.0, static_cast<double>(dims[k] - 1)));
    }
    return c;
  }

  // Support length in cell units: the reach handed to mask_keeps.
  [[nodiscard]] double reach(Real h) const { return static_cast<double>(h) * inv_cell; }

  // The mask for the largest support; smaller supports skip cells per particle with mask_keeps.
  [[nodiscard]] std::vector<MaskCell<Dim>> mask() const {
    return h_mask<Dim>(one_cell ? 0.0 : max_h * inv_cell);
  }

  [[nodiscard]] bool inside(const Cell& c) const {
    for (int k = 0; k < Dim; ++k)
      if (c[k] < 0 || c[k] >= dims[k]) return false;
    return true;
  }
};

namespace detail {
// Smallest prime >= v (v small enough for trial division: table sizes, not keys).
inline std::size_t next_prime(std::size_t v) {
  if (v <= 2) return 2;
  for (std::size_t p = v | 1U;; p += 2) {
    bool prime = true;
    for (std::size_t d = 3; d * d <= p; d += 2)
      if (p % d == 0) {
        prime = false;
        break;
      }
    if (prime) return p;
  }
}
}  // namespace detail

template <int Dim, class Real>
class SpatialHash {
 public:
  using Point = Vec<Dim, Real>;
  using Cell = typename CellFrame<Dim, Real>::Cell;

  explicit SpatialHash(const SearchOptions& opt = {})
      : subdivision_(opt.subdivision), table_size_option_(opt.hash_table_size) {}

  // Default table size M when SearchOptions::hash_table_size is 0: the smallest prime >= 2n, which
  // keeps the expected bucket load below one non-empty cell.
  static std::size_t default_table_size(std::size_t n) { return detail::next_prime(2 * n); }

  void build(std::span<const Point> x, std::span<const Real> h) {
    x_ = x;
    h_ = h;
    const std::size_t n = x.size();
    frame_.build(x, h, subdivision_, "spatial-hash");
    mask_ = frame_.mask();
    table_size_ = table_size_option_ > 0 ? table_size_option_ : default_table_size(n);
    if (table_size_ >= std::numeric_limits<std::uint32_t>::max()) {
      std::ostringstream os;
      os << "spatial-hash: table size M = " << table_size_ << " exceeds 32-bit bucket numbers";
      throw CapacityError(os.str());
    }

    // Counting sort of the particles by bucket: bucket b holds entries [start[b], start[b+1]),
    // in increasing particle index, so the table does not depend on the thread count.
    std::vector<std::uint32_t> bucket_of(n);
    const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < count; ++i)
      bucket_of[static_cast<std::size_t>(i)] = bucket(frame_.cell_of(x[static_cast<std::size_t>(i)]));
    start_.assign(table_size_ + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++start_[bucket_of[i] + 1];
    for (std::size_t b = 0; b < table_size_; ++b) start_[b + 1] += start_[b];
    entries_.resize(n);
    std::vector<std::uint32_t> cursor(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      Entry& e = entries_[cursor[bucket_of[i]]++];
      e.x = x[i];
      e.cell = frame_.cell_of(x[i]);
      e.index = static_cast<std::uint32_t>(i);
    }
  }

  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    const auto count = static_cast<std::int64_t>(x_.size());
    std::uint64_t tests = 0;
#pragma omp parallel reduction(+ : tests)
    {
      // The mask cells of one particle hash to scattered buckets: every bucket is a likely cache
      // miss (the cost the paper attributes to Spatial Hashing). Their addresses are all known up
      // front, so they are gathered first and prefetched, then the buckets are scanned.
      struct Visit {
        Cell cell;
        std::uint32_t begin, end;
      };
      std::vector<Visit> visits;
      visits.reserve(mask_.size());
#pragma omp for schedule(static)
      for (std::int64_t ii = 0; ii < count; ++ii) {
        const auto i = static_cast<std::uint32_t>(ii);
        const Point xi = x_[i];
        const Real hi2 = h_[i] * h_[i];
        const double reach = frame_.reach(h_[i]);
        const Cell home = frame_.cell_of(xi);
        visits.clear();
        for (const MaskCell<Dim>& m : mask_) {
          if (!mask_keeps(m.gap2, reach)) continue;
          Cell c;
          for (int k = 0; k < Dim; ++k) c[k] = home[k] + m.offset[k];
          if (!frame_.inside(c)) continue;  // no particle lives outside the bounding box
          const std::uint32_t b = bucket(c);
          __builtin_prefetch(&start_[b]);
          visits.push_back({c, b, 0});
        }
        for (Visit& v : visits) {
          const std::uint32_t b = v.begin;
          v.begin = start_[b];
          v.end = start_[b + 1];
          __builtin_prefetch(&entries_[v.begin]);
        }
        for (const Visit& v : visits) {
          for (std::uint32_t e = v.begin; e < v.end; ++e) {
            const Entry& en = entries_[e];
            if (en.cell != v.cell || en.index == i) continue;  // another cell sharing the bucket
            ++tests;
            const Real r2 = distance2(xi, en.x);
            if (r2 <= hi2) f(i, en.index, r2);
          }
        }
      }
    }
    return tests;
  }

  [[nodiscard]] std::size_t memory_bytes() const {
    return start_.capacity() * sizeof(std::uint32_t) + entries_.capacity() * sizeof(Entry) +
           mask_.capacity() * sizeof(MaskCell<Dim>);
  }
  [[nodiscard]] std::size_t table_size() const {
    return table_size_;
  }

 private:
  struct Entry {
    Point x;  // copy of the position, so a bucket scan touches one array
    Cell cell;
    std::uint32_t index;
  };

  // eq. 15: hash(i, j, k) = (i p1 xor j p2 xor k p3) mod M, Teschner's primes.
  [[nodiscard]] std::uint32_t bucket(const Cell& c) const {
    constexpr std::uint64_t kPrimes[3] = {73856093U, 19349663U, 83492791U};
    std::uint64_t v = 0;
    for (int k = 0; k < Dim; ++k) v ^= static_cast<std::uint64_t>(c[k]) * kPrimes[k];
    return static_cast<std::uint32_t>(v % table_size_);
  }

  int subdivision_;
  std::size_t table_size_option_;
  std::size_t table_size_ = 1;
  std::span<const Point> x_;
  std::span<const Real> h_;
  CellFrame<Dim, Real> frame_;
  std::vector<MaskCell<Dim>> mask_;
  std::vector<std::uint32_t> start_;
  std::vector<Entry> entries_;
};

}  // namespace cellsph
