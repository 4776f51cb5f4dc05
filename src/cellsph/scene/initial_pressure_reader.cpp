// /initial_pressure (docs/scenes.md, "Top level"): with "hydrostatic", the fluid starts at rest in
// equilibrium under gravity, each particle with the pressure of the fluid above it and the mass that gives
// its lattice site the state equation's density for it.
#include "cellsph/scene/scene_readers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cellsph/physics/kernels.hpp"

namespace cellsph::scene_detail {

namespace {

// Length of the ray x + t d (t >= 0) inside the box (slab method).
template <int Dim>
double ray_length_in(const Aabb<Dim>& b, const std::array<double, Dim>& x, const std::array<double, Dim>& d) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < Dim; ++a) {
    if (d[a] == 0) {
      if (x[a] < b.lo[a] || x[a] > b.hi[a]) return 0;
      continue;
    }
    const double u = (b.lo[a] - x[a]) / d[a], v = (b.hi[a] - x[a]) / d[a];
    t0 = std::max(t0, std::min(u, v));
    t1 = std::min(t1, std::max(u, v));
  }
  return std::max(0.0, t1 - t0);
}

// Whether the point x lies strictly inside the box b (a block's lattice sites are half a pitch inside).
template <int Dim>
bool strictly_inside(const Aabb<Dim>& b, const std::array<double, Dim>& x) {
  for (int a = 0; a < Dim; ++a) {
    const auto k = static_cast<std::size_t>(a);
    if (!(x[k] > b.lo[k] && x[k] < b.hi[k])) return false;
  }
  return true;
}

// sum_k W(|k pitch|) over the whole lattice of these pitches (k integer, self included): the summation
// density of a lattice site inside the fluid is m times this, which differs from 1 / spacing^Dim by a
// fraction of a percent (enough for a pressure of the order of rho0 g H at the dam breaks' sound speed).
template <int Dim, class Real>
double lattice_kernel_sum(const SolverConfig<Dim, Real>& cfg, const std::array<double, 3>& pitch) {
  double smallest = pitch[0];
  for (int a = 1; a < Dim; ++a) smallest = std::min(smallest, pitch[static_cast<std::size_t>(a)]);
  const int K = static_cast<int>(std::ceil(double(cfg.support) / smallest));
  double sum = 0;
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    std::array<int, Dim> k;
    k.fill(-K);
    while (true) {
      double r2 = 0;
      for (int a = 0; a < Dim; ++a) {
        const double d = double(k[a]) * pitch[static_cast<std::size_t>(a)];
        r2 += d * d;
      }
      sum += double(w.W2(static_cast<Real>(r2)));
      int a = 0;
      while (a < Dim && ++k[a] > K) k[a++] = -K;
      if (a == Dim) break;
    }
  });
  return sum;
}

// Fluid at rest under gravity: every fluid particle gets the pressure of the fluid above it,
// p = |g| sum_b rho0_b L_b (L_b: the length of the ray from the particle against gravity inside fluid
// block b), and the mass at which the summation density of its lattice site is the state equation's
// density for p: m = rho(p) / lattice_kernel_sum. A column then starts in equilibrium instead of
// falling onto itself while its pressure builds (and without the uniform pressure that the lattice
// sum's bias gives with m = rho0 spacing^Dim). Blocks do not overlap; walls and obstacles above carry no
// weight. A phase whose mass the scene sets keeps it (times the volume factor of a stretched lattice). A
// particle of a block whose lattice is stretched (the spacing does not divide it: solver/initial.hpp) takes
// the kernel sum of that block's lattice.
// DFSPH has no equation of state (its fluid is incompressible): there every mass is rho0 over the lattice
// sum, so that the summation density of each lattice site is rho0 exactly, and the solver finds the
// pressure itself. (The masses compressed by the scene's eos would make a DFSPH column explode in its
// first steps: lobovsky-2014 under DFSPH loses a particle at t = 1 ms. The first solve gets no warm start
// of rho0 g depth: with one it takes 6 sweeps instead of 2.)
template <int Dim, class Real>
void start_hydrostatic(Particles<Dim, Real>& p, const SolverConfig<Dim, Real>& cfg, double spacing,
                       const std::vector<bool>& mass_given, const FluidBlocks<Dim>& fluids,
                       const std::vector<double>& extra) {
  const auto& blocks = fluids.blocks;
  const auto& block_phase = fluids.phase;
  double g2 = 0;
  for (int a = 0; a < Dim; ++a) g2 += double(cfg.gravity[a]) * double(cfg.gravity[a]);
  const double g = std::sqrt(g2);
  const std::array<double, 3> plain{spacing, spacing, spacing};
  const double volume = 1 / lattice_kernel_sum(cfg, plain);
  // Per block: the volume of a particle of its lattice, and its mass over the plain lattice's.
  std::vector<double> block_volume(blocks.size(), volume), block_factor(blocks.size(), 1);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (int a = 0; a < Dim; ++a) block_factor[b] *= fluids.pitch[b][static_cast<std::size_t>(a)] / spacing;
    if (block_factor[b] != 1) block_volume[b] = 1 / lattice_kernel_sum(cfg, fluids.pitch[b]);
  }
  std::array<double, Dim> up{};
  for (int a = 0; a < Dim; ++a) up[static_cast<std::size_t>(a)] = g > 0 ? -double(cfg.gravity[a]) / g : 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != static_cast<std::uint8_t>(ParticleKind::Fluid)) continue;
    std::array<double, Dim> x{};
    for (int a = 0; a < Dim; ++a) x[static_cast<std::size_t>(a)] = double(p.x[i][a]);
    double pressure = extra[i];
    double own_volume = volume, own_factor = 1;
    for (std::size_t b = 0; b < blocks.size(); ++b)
      if (strictly_inside<Dim>(blocks[b], x)) {
        own_volume = block_volume[b];
        own_factor = block_factor[b];
        break;
      }
    if (g > 0)
      for (std::size_t b = 0; b < blocks.size(); ++b)
        pressure += g * double(cfg.phases[static_cast<std::size_t>(block_phase[b])].rest_density) *
                    ray_length_in<Dim>(blocks[b], x, up);
    const auto ph = static_cast<std::size_t>(p.phase[i]);
    const Real rho0 = cfg.phases[ph].rest_density;
    const bool incompressible = implicit_pressure(cfg.model);
    const double rho =
        incompressible ? double(rho0) : double(cfg.eos.density(static_cast<Real>(pressure), rho0));
    p.m[i] = mass_given[ph] ? static_cast<Real>(double(cfg.phases[ph].mass) * own_factor * rho / double(rho0))
                            : static_cast<Real>(rho * own_volume);
    // The continuity density starts from it (summation density recomputes it from the masses).
    if (p.rho.size() == p.size()) p.rho[i] = static_cast<Real>(rho);
  }
}

// The hydrostatic pressure of each shaped fluid volume's own weight, rho0 |g| (n + 1/2) spacing for a
// particle with n particles of its volume above it in its lattice column (gravity along an axis).
template <int Dim, class Real>
std::vector<double> shaped_fluid_pressure(const JsonReader& r, double spacing,
                                          const SolverConfig<Dim, Real>& cfg, const FluidBlocks<Dim>& fluids,
                                          const Particles<Dim, Real>& p) {
  std::vector<double> extra(p.size(), 0);
  if (fluids.shape_ranges.empty()) return extra;
  int axis = -1, nonzero = 0;
  for (int a = 0; a < Dim; ++a)
    if (cfg.gravity[a] != 0) {
      axis = a;
      ++nonzero;
    }
  if (nonzero == 0) return extra;
  if (nonzero > 1)
    r.fail("initial_pressure", "\"hydrostatic\" with a shaped fluid volume needs gravity along one axis");
  const double g = std::abs(double(cfg.gravity[axis]));
  const double up = cfg.gravity[axis] < 0 ? 1 : -1;
  for (std::size_t f = 0; f < fluids.shape_ranges.size(); ++f) {
    const auto [first, end] = fluids.shape_ranges[f];
    const double rho0 = double(cfg.phases[static_cast<std::size_t>(fluids.shape_phase[f])].rest_density);
    // Sorted by column, then by height against gravity.
    std::vector<std::pair<std::array<long, 3>, std::size_t>> keys;
    keys.reserve(end - first);
    for (std::size_t i = first; i < end; ++i) {
      std::array<long, 3> k{0, 0, 0};
      int slot = 0;
      for (int a = 0; a < Dim; ++a)
        if (a != axis) k[static_cast<std::size_t>(slot++)] = std::lround(double(p.x[i][a]) / spacing - 0.5);
      k[2] = std::lround(up * double(p.x[i][axis]) / spacing);
      keys.emplace_back(k, i);
    }
    std::sort(keys.begin(), keys.end());
    for (std::size_t c = 0; c < keys.size();) {
      std::size_t e = c;
      while (e < keys.size() && keys[e].first[0] == keys[c].first[0] && keys[e].first[1] == keys[c].first[1])
        ++e;
      for (std::size_t q = c; q < e; ++q)
        extra[keys[q].second] = rho0 * g * (double(e - q - 1) + 0.5) * spacing;
      c = e;
    }
  }
  return extra;
}

}  // namespace

template <int Dim, class Real>
void read_initial_pressure(JsonReader& r, double spacing, const SolverConfig<Dim, Real>& cfg,
                           const PhaseTable& phases, const FluidBlocks<Dim>& fluids,
                           Particles<Dim, Real>& p) {
  if (r.choice("initial_pressure", "zero", {"zero", "hydrostatic"}) == "hydrostatic")
    start_hydrostatic(p, cfg, spacing, phases.mass_given, fluids,
                      shaped_fluid_pressure(r, spacing, cfg, fluids, p));
}

#define CELLSPH_INITIAL_PRESSURE_INSTANTIATE(D, R)                                          \
  template void read_initial_pressure<D, R>(JsonReader&, double, const SolverConfig<D, R>&, \
                                            const PhaseTable&, const FluidBlocks<D>&, Particles<D, R>&);
CELLSPH_INITIAL_PRESSURE_INSTANTIATE(2, float)
CELLSPH_INITIAL_PRESSURE_INSTANTIATE(2, double)
CELLSPH_INITIAL_PRESSURE_INSTANTIATE(3, float)
CELLSPH_INITIAL_PRESSURE_INSTANTIATE(3, double)
#undef CELLSPH_INITIAL_PRESSURE_INSTANTIATE

}  // namespace cellsph::scene_detail
