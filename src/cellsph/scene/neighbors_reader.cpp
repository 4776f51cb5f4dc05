// /neighbors (docs/scenes.md, "neighbors"): the neighbour search, its Verlet skin and the reorder; and
// /parallel (docs/scenes.md, "parallel"): how a run across MPI ranks balances its work.
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

template <int Dim, class Real>
void read_neighbors(JsonReader& r, SolverConfig<Dim, Real>& cfg) {
  if (!r.has("neighbors")) return;
  auto nr = r.child("neighbors");
  std::vector<std::string> methods;
  for (Method m : kAllMethods) methods.emplace_back(method_name(m));
  cfg.search.method = *parse_method(nr.choice("method", "cell-index", methods));
  cfg.search.subdivision = static_cast<int>(nr.integer("subdivision", 1, 1, 16));
  cfg.search.hash_table_size = static_cast<std::size_t>(nr.integer("hash_table_size", 0, 0, 4294967294L));
  cfg.verlet_skin = static_cast<Real>(nr.number("skin", double(cfg.verlet_skin), 0, 1));
  cfg.reorder_every = static_cast<std::uint32_t>(
      nr.integer("reorder_every", static_cast<long>(cfg.reorder_every), 0, 1000000));
  nr.finish();
}

template <int Dim, class Real>
void read_parallel(JsonReader& r, SolverConfig<Dim, Real>& cfg) {
  if (!r.has("parallel")) return;
  auto pr = r.child("parallel");
  cfg.rebalance_threshold = pr.number("rebalance_threshold", cfg.rebalance_threshold, 1e-6, 10);
  pr.finish();
}

#define CELLSPH_NEIGHBORS_INSTANTIATE(D, R)                             \
  template void read_neighbors<D, R>(JsonReader&, SolverConfig<D, R>&); \
  template void read_parallel<D, R>(JsonReader&, SolverConfig<D, R>&);
CELLSPH_NEIGHBORS_INSTANTIATE(2, float)
CELLSPH_NEIGHBORS_INSTANTIATE(2, double)
CELLSPH_NEIGHBORS_INSTANTIATE(3, float)
CELLSPH_NEIGHBORS_INSTANTIATE(3, double)
#undef CELLSPH_NEIGHBORS_INSTANTIATE

}  // namespace cellsph::scene_detail
