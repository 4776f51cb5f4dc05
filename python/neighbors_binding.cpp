// cellsph.neighbors, cellsph.count_neighbors and cellsph.NeighborSearch: the library's NeighborSearch
// (src/cellsph/neighbors/neighbor_search.hpp) on NumPy arrays. The points are read in place (no copy for a
// C-contiguous float32/float64 array); the CSR lists the search writes are handed to NumPy as they are
// (the arrays own the search's vectors: no copy out either). The GIL is released during the search.
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bindings.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"

namespace cellsph::python {
namespace {

// A NumPy array that owns `v` (moved to the heap; freed when the array is), viewed as elements of type T
// (same size: the uint64 offsets are shown as int64, all far below 2^63).
template <class T, class U, class A>
py::array owning_array(std::vector<U, A>&& v) {
  static_assert(sizeof(T) == sizeof(U));
  using Vector = std::vector<U, A>;
  auto* heap = new Vector(std::move(v));
  py::capsule owner(heap, [](void* p) { delete static_cast<Vector*>(p); });
  const auto n = static_cast<py::ssize_t>(heap->size());
  return py::array(py::dtype::of<T>(), {n}, {static_cast<py::ssize_t>(sizeof(T))}, heap->data(), owner);
}

Method method_arg(const std::string& name) {
  const auto m = parse_method(name);
  if (!m)
    throw ArgumentError("method: unknown method '" + name + "' (expected one of " +
                        method_names_joined(", ") + ")");
  return *m;
}

int subdivision_arg(int subdivision) {
  if (subdivision < 1)
    throw ArgumentError("subdivision: must be an integer >= 1, got " + std::to_string(subdivision));
  return subdivision;
}

// The checked inputs of one search: points (contiguous, finite), and either a radius or per-point h.
struct Query {
  py::array points;
  std::optional<double> radius;
  py::array h;  // empty unless per-point
  int dim = 0;
  bool f32 = false;
  std::size_t n = 0;
};

Query query_args(const py::handle& points, const std::optional<double>& radius, const py::handle& h) {
  Query q;
  q.points = points_array(points);
  q.dim = static_cast<int>(q.points.shape(1));
  q.f32 = py::isinstance<py::array_t<float>>(q.points);
  q.n = static_cast<std::size_t>(q.points.shape(0));
  const bool has_h = !h.is_none();
  if (radius && has_h)
    throw ArgumentError("radius and h: give one, not both (radius=" + repr_text(py::float_(*radius)) + ")");
  if (!radius && !has_h) throw ArgumentError("radius: required (or h, one support length per point)");
  if (radius) q.radius = check_radius(*radius);
  if (has_h) q.h = support_array(h, q.n, q.f32);
  return q;
}

// Builds `ns` for the query. Call without the GIL.
template <int Dim, class Real>
std::span<const Vec<Dim, Real>> points_span(const Query& q) {
  return {static_cast<const Vec<Dim, Real>*>(q.points.data()), q.n};
}

// Builds the search on `threads` threads with the GIL released (the points stay alive in q).
template <int Dim, class Real>
void build(NeighborSearch<Dim, Real>& ns, const Query& q, int threads) {
  py::gil_scoped_release nogil;
  ScopedThreads scoped(threads);
  const auto x = points_span<Dim, Real>(q);
  if (q.radius)
    ns.build(x, static_cast<Real>(*q.radius));
  else
    ns.build(x, std::span<const Real>(static_cast<const Real*>(q.h.data()), q.n));
}

// Euclidean distance of every listed pair, in the points' precision (the search's own distance2).
template <int Dim, class Real>
std::vector<Real> pair_distances(const Query& q, const NeighborList& list) {
  const auto x = points_span<Dim, Real>(q);
  std::vector<Real> d(list.indices.size());
  parallel_for(list.size(), [&](std::size_t i) {
    for (std::uint64_t k = list.offsets[i]; k < list.offsets[i + 1]; ++k)
      d[k] = std::sqrt(distance2(x[i], x[list.indices[k]]));
  });
  return d;
}

// find_all on a built search -> (offsets, indices[, distances]).
template <int Dim, class Real>
py::tuple find_all(NeighborSearch<Dim, Real>& ns, const Query& q, bool distances, int threads) {
  NeighborList list;
  std::vector<Real> d;
  {
    py::gil_scoped_release nogil;
    ScopedThreads scoped(threads);
    ns.find_all(list);
    if (distances) d = pair_distances<Dim, Real>(q, list);
  }
  if (list.offsets.empty()) list.offsets.assign(1, 0);  // n = 0: one offset
  py::array offsets = owning_array<std::int64_t>(std::move(list.offsets));
  py::array indices = owning_array<std::uint32_t>(std::move(list.indices));
  if (distances) return py::make_tuple(offsets, indices, owning_array<Real>(std::move(d)));
  return py::make_tuple(offsets, indices);
}

template <int Dim, class Real>
py::array count(const NeighborSearch<Dim, Real>& ns, std::size_t n, int threads) {
  std::vector<std::int64_t> counts(n, 0);
  {
    py::gil_scoped_release nogil;
    ScopedThreads scoped(threads);
    // The visitor runs all pairs of one i on one thread: counting into counts[i] is race free.
    ns.for_each_pair([&](std::uint32_t i, std::uint32_t, Real) { ++counts[i]; });
  }
  return owning_array<std::int64_t>(std::move(counts));
}

template <class F>
auto dispatch(const Query& q, F&& f) {
  if (q.dim == 2) return q.f32 ? f.template operator()<2, float>() : f.template operator()<2, double>();
  return q.f32 ? f.template operator()<3, float>() : f.template operator()<3, double>();
}

// sort_rows = false: Cell Indexing leaves each row in its own order (SearchOptions::sorted_rows).
SearchOptions search_options(const std::string& method, int subdivision, bool sort_rows = true) {
  return {
      .method = method_arg(method), .subdivision = subdivision_arg(subdivision), .sorted_rows = sort_rows};
}

py::tuple neighbors_fn(const py::handle& points, std::optional<double> radius, const py::handle& h,
                       const std::string& method, int threads, int subdivision, bool return_distances,
                       bool sort_rows) {
  const SearchOptions opt = search_options(method, subdivision, sort_rows);
  check_threads(threads);
  const Query q = query_args(points, radius, h);
  return dispatch(q, [&]<int Dim, class Real>() {
    NeighborSearch<Dim, Real> ns(opt);
    build(ns, q, threads);
    return find_all(ns, q, return_distances, threads);
  });
}

py::array count_fn(const py::handle& points, std::optional<double> radius, const py::handle& h,
                   const std::string& method, int threads, int subdivision) {
  const SearchOptions opt = search_options(method, subdivision);
  check_threads(threads);
  const Query q = query_args(points, radius, h);
  return dispatch(q, [&]<int Dim, class Real>() {
    NeighborSearch<Dim, Real> ns(opt);
    build(ns, q, threads);
    return count(ns, q.n, threads);
  });
}

// The reusable search object: its structures (sort buffers, cell tables) stay allocated between builds,
// which is what repeated searches on moving points need. It keeps the arrays of the last build() alive
// (some methods read the points again in find_all).
class PyNeighborSearch {
 public:
  PyNeighborSearch(const std::string& method, int subdivision, int threads, bool sort_rows)
      : opt_(search_options(method, subdivision, sort_rows)), threads_(check_threads(threads)) {}

  void build(const py::handle& points, std::optional<double> radius, const py::handle& h) {
    Query q = query_args(points, radius, h);
    std::lock_guard lock(mutex_);
    built_ = false;  // until this build succeeds (a library error leaves the structure half built)
    dispatch(q, [&]<int Dim, class Real>() {
      using NS = NeighborSearch<Dim, Real>;
      if (!std::holds_alternative<NS>(ns_)) ns_.template emplace<NS>(opt_);
      cellsph::python::build(std::get<NS>(ns_), q, threads_);
      return 0;
    });
    q_ = std::move(q);
    built_ = true;
  }

  py::tuple find_all(bool distances) {
    require_built("find_all");
    std::lock_guard lock(mutex_);
    return dispatch(q_, [&]<int Dim, class Real>() {
      return cellsph::python::find_all(std::get<NeighborSearch<Dim, Real>>(ns_), q_, distances, threads_);
    });
  }

  py::array count_all() {
    require_built("count");
    std::lock_guard lock(mutex_);
    return dispatch(q_, [&]<int Dim, class Real>() {
      return count(std::get<NeighborSearch<Dim, Real>>(ns_), q_.n, threads_);
    });
  }

  [[nodiscard]] py::dict stats() const {
    py::dict d;
    if (!built_) return d;
    const SearchStats s =
        dispatch(q_, [&]<int Dim, class Real>() { return std::get<NeighborSearch<Dim, Real>>(ns_).stats(); });
    d["build_ms"] = s.build_ms;
    d["query_ms"] = s.query_ms;
    d["pairs"] = s.pairs;
    d["candidates"] = s.candidates;
    d["memory_bytes"] = s.memory_bytes;
    return d;
  }

  [[nodiscard]] std::string method() const { return std::string(method_name(opt_.method)); }
  [[nodiscard]] int subdivision() const { return opt_.subdivision; }
  [[nodiscard]] bool sort_rows() const { return opt_.sorted_rows; }
  [[nodiscard]] int threads() const { return threads_; }
  [[nodiscard]] std::size_t size() const { return built_ ? q_.n : 0; }
  [[nodiscard]] py::object dim() const {
    return built_ ? py::object(py::int_(q_.dim)) : py::object(py::none());
  }
  [[nodiscard]] py::object dtype() const {
    return built_ ? py::object(q_.points.dtype()) : py::object(py::none());
  }
  [[nodiscard]] py::object points() const { return built_ ? py::object(q_.points) : py::object(py::none()); }

 private:
  void require_built(const char* what) const {
    if (!built_)
      throw py::value_error(std::string("NeighborSearch.") + what + "(): call build(points, ...) first");
  }

  SearchOptions opt_;
  int threads_;
  std::variant<std::monostate, NeighborSearch<2, float>, NeighborSearch<2, double>, NeighborSearch<3, float>,
               NeighborSearch<3, double>>
      ns_;
  Query q_;
  bool built_ = false;
  std::mutex mutex_;  // one search at a time per object (the GIL is released during it)
};

constexpr const char* kNeighborsDoc = R"doc(Every neighbour of every point, as CSR arrays.

j is a neighbour of i when j != i and |x_i - x_j| <= r_i, with r_i = radius, or h[i] when per-point
support lengths are given. The search is exact (every method returns precisely the brute-force set).

Parameters
----------
points : ndarray, shape (n, 2) or (n, 3), float32 or float64
    Read in place when C-contiguous (otherwise copied once). Coordinates must be finite.
radius : float, optional
    One support length for all points (finite, > 0).
h : ndarray, shape (n,), optional
    One support length per point (finite, >= 0), converted to the points' dtype. Give radius or h.
method : str
    "cell-index" (default), "spatial-hash", "sorted-grid", "kd-tree" or "all-pairs".
threads : int
    OpenMP threads; 0 = all cores.
subdivision : int
    Cell Indexing / grid subdivision factor H >= 1 (cells of size h / H).
return_distances : bool
    Also return the distance of each listed pair (points' dtype).
sort_rows : bool
    True (default): every row ascending, the same arrays whatever the method or the thread count.
    False: "cell-index" leaves each row in its own order (cell by cell, the same for the same points,
    method and subdivision) and skips sorting it; the other methods' rows stay ascending.

Returns
-------
offsets : ndarray of int64, shape (n + 1,)
indices : ndarray of uint32
    Neighbours of i are indices[offsets[i]:offsets[i + 1]], ascending unless sort_rows=False.
distances : ndarray, only with return_distances=True
    Aligned with indices.

The GIL is released during the search. The arrays own the search's output (nothing is copied out).
Raises ValueError naming the argument for wrong shapes, dtypes, non-finite values, bad radius or h.)doc";

}  // namespace

void register_neighbors(py::module_& m) {
  using namespace pybind11::literals;
  m.def("neighbors", &neighbors_fn, kNeighborsDoc, "points"_a, "radius"_a = py::none(), "h"_a = py::none(),
        "method"_a = "cell-index", "threads"_a = 0, "subdivision"_a = 1, "return_distances"_a = false,
        "sort_rows"_a = true);
  m.def("count_neighbors", &count_fn,
        "The number of neighbours of every point (int64, shape (n,)), without building the lists.\n\n"
        "Same arguments and neighbour relation as neighbors().",
        "points"_a, "radius"_a = py::none(), "h"_a = py::none(), "method"_a = "cell-index", "threads"_a = 0,
        "subdivision"_a = 1);
  m.def(
      "methods",
      [] {
        py::list l;
        for (const Method me : kAllMethods) l.append(std::string(method_name(me)));
        return l;
      },
      "The names of the neighbour-search methods.");

  py::class_<PyNeighborSearch>(m, "NeighborSearch",
                               R"doc(A reusable neighbour search, for repeated queries on moving points.

    ns = cellsph.NeighborSearch(method="cell-index", threads=0)
    for step in range(100):
        ns.build(points, radius=0.02)      # keeps its buffers from the last build
        offsets, indices = ns.find_all()

find_all() and count() read the arrays given to the last build(): call build() again after changing them.
One search at a time per object (calls from several Python threads wait for each other).)doc")
      .def(py::init<const std::string&, int, int, bool>(), "method"_a = "cell-index", "subdivision"_a = 1,
           "threads"_a = 0, "sort_rows"_a = true)
      .def("build", &PyNeighborSearch::build,
           "Builds the structure for points (n, 2|3) float32/float64 with one radius or per-point h.",
           "points"_a, "radius"_a = py::none(), "h"_a = py::none())
      .def("find_all", &PyNeighborSearch::find_all,
           "(offsets int64, indices uint32[, distances]) of the last build; rows ascending unless the "
           "search was made with sort_rows=False.",
           "return_distances"_a = false)
      .def("count", &PyNeighborSearch::count_all, "Neighbours per point (int64) of the last build.")
      .def_property_readonly("stats", &PyNeighborSearch::stats,
                             "The last build/find_all: build_ms, query_ms, pairs, candidates, memory_bytes.")
      .def_property_readonly("method", &PyNeighborSearch::method, "The search method's name.")
      .def_property_readonly("subdivision", &PyNeighborSearch::subdivision, "The subdivision factor H.")
      .def_property_readonly("sort_rows", &PyNeighborSearch::sort_rows,
                             "False: cell-index leaves each row in its own order (see neighbors()).")
      .def_property_readonly("threads", &PyNeighborSearch::threads, "OpenMP threads (0 = all cores).")
      .def_property_readonly("size", &PyNeighborSearch::size, "Points of the last build (0 before).")
      .def_property_readonly("dim", &PyNeighborSearch::dim, "2 or 3 (None before the first build).")
      .def_property_readonly("dtype", &PyNeighborSearch::dtype,
                             "float32 or float64 (None before the first build).")
      .def_property_readonly("points", &PyNeighborSearch::points,
                             "The points array of the last build (read in place).");
}

}  // namespace cellsph::python
