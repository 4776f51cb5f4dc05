#include "cellsph/solver/simulation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/boundaries.hpp"

namespace cellsph {

namespace {

constexpr std::uint8_t kFluid = static_cast<std::uint8_t>(ParticleKind::Fluid);
constexpr std::uint8_t kBoundary = static_cast<std::uint8_t>(ParticleKind::Boundary);

// Empty when `id` is a permutation of 0..n-1, otherwise what is wrong with it.
std::string id_permutation_error(const std::vector<std::uint32_t>& id) {
  std::vector<std::uint8_t> seen(id.size(), 0);
  for (std::size_t i = 0; i < id.size(); ++i) {
    if (id[i] >= id.size() || seen[id[i]]) {
      std::ostringstream os;
      os << "particle " << i << " has id " << id[i]
         << (id[i] >= id.size() ? " (ids must be below the particle count " + std::to_string(id.size()) + ")"
                                : " (another particle has it too)");
      return os.str();
    }
    seen[id[i]] = 1;
  }
  return {};
}

// Z-order (Morton) key of a cell: the bits of the cell coordinates interleaved, so that cells close in
// space are mostly close in the key and each block of 2^Dim, 4^Dim, ... cells is contiguous.
template <int Dim>
std::uint64_t morton_key(const std::uint64_t (&c)[Dim]) {
  constexpr int bits = 64 / Dim;
  std::uint64_t key = 0;
  for (int b = 0; b < bits; ++b)
    for (int a = 0; a < Dim; ++a) key |= ((c[a] >> b) & 1u) << (b * Dim + a);
  return key;
}

}  // namespace

template <int Dim, class Real>
Simulation<Dim, Real>::Simulation(Config config, Particles<Dim, Real> particles)
    : cfg_(std::move(config)), p_(std::move(particles)), search_(cfg_.search) {
  cfg_.validate();
  const std::size_t n = p_.x.size();
  // Inputs that may be left empty get their defaults; any other size mismatch is an error.
  auto complete = [n](auto& field, const char* name, auto value) {
    if (field.empty()) field.assign(n, value);
    if (field.size() != n) {
      std::ostringstream os;
      os << "particles: field '" << name << "' has " << field.size() << " entries, positions have " << n;
      throw InputError(os.str());
    }
  };
  complete(p_.v, "velocity", V{});
  complete(p_.m, "mass", Real(0));
  complete(p_.phase, "phase", std::int32_t{0});
  complete(p_.kind, "kind", kFluid);
  p_.f.assign(n, V{});
  p_.rho.assign(n, Real(0));
  p_.p.assign(n, Real(0));
  p_.h.assign(n, cfg_.support);
  p_.color.assign(n, Real(0));
  p_.mu.assign(n, Real(0));
  complete(p_.level, "level", std::int32_t{0});
  complete(p_.tick, "tick", std::int64_t{0});
  // Ids: empty, or all 0 as left by builders that resize the field list, mean the input order.
  if (std::all_of(p_.id.begin(), p_.id.end(), [](std::uint32_t k) { return k == 0; })) p_.id.clear();
  if (p_.id.empty()) {
    CELLSPH_CHECK(n <= std::numeric_limits<std::uint32_t>::max(), n << " particles do not fit 32-bit ids");
    p_.id.resize(n);
    for (std::size_t i = 0; i < n; ++i) p_.id[i] = static_cast<std::uint32_t>(i);
  }
  complete(p_.id, "id", std::uint32_t{0});
  if (const auto err = id_permutation_error(p_.id); !err.empty()) throw InputError("particles: " + err);
  rho0_.assign(n, Real(0));

  fluid_count_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto ph = p_.phase[i];
    if (ph < 0 || static_cast<std::size_t>(ph) >= cfg_.phases.size()) {
      std::ostringstream os;
      os << "particles: particle " << i << " has phase " << ph << ", the phase table has "
         << cfg_.phases.size() << " entries";
      throw InputError(os.str());
    }
    if (p_.kind[i] != kFluid && p_.kind[i] != kBoundary) {
      std::ostringstream os;
      os << "particles: particle " << i << " has kind " << int(p_.kind[i]) << " (0 fluid, 1 boundary)";
      throw InputError(os.str());
    }
    if (!all_finite(p_.x[i]) || !all_finite(p_.v[i])) {
      std::ostringstream os;
      os << "particles: particle " << i << " has a non-finite position or velocity";
      throw InputError(os.str());
    }
    const auto& phase = cfg_.phases[static_cast<std::size_t>(ph)];
    rho0_[i] = phase.rest_density;
    p_.rho[i] = phase.rest_density;
    p_.color[i] = phase.color;
    p_.mu[i] = phase.viscosity;
    if (p_.kind[i] == kFluid) {
      ++fluid_count_;
      if (p_.m[i] <= 0) p_.m[i] = phase.mass;
      if (!(p_.m[i] > 0 && std::isfinite(p_.m[i]))) {
        std::ostringstream os;
        os << "particles: fluid particle " << i << " has mass " << p_.m[i] << " and phase '" << phase.name
           << "' gives none (phases[" << ph << "].mass)";
        throw InputError(os.str());
      }
    } else {
      p_.v[i] = V{};
      if (!(p_.m[i] >= 0 && std::isfinite(p_.m[i]))) {
        std::ostringstream os;
        os << "particles: boundary particle " << i << " has weight (mass) " << p_.m[i];
        throw InputError(os.str());
      }
    }
  }
  for (const auto& ph : cfg_.phases) any_tension_ = any_tension_ || ph.sigma > 0;
  wall_states_ = cfg_.wall_model != WallModel::Akinci && fluid_count_ < n;
  f_pressure_.assign(n, V{});
  fluid_.clear();
  fluid_.reserve(fluid_count_);
  boundary_.clear();
  // Default 0.15 h: 1.5x the pairs in the lists (3D), rebuilt every few steps at the dam break's speeds.
  skin_ = cfg_.verlet_skin * cfg_.support;
  search_h_.assign(n, Real(0));
  for (std::size_t i = 0; i < n; ++i) {
    if (p_.kind[i] != kFluid) {
      boundary_.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    fluid_.push_back(static_cast<std::uint32_t>(i));
    search_h_[i] = p_.h[i] + skin_;
  }
  // Boundary particles never move: one reorder puts them in cell order for the whole run (before their
  // weights, whose sums then run in that order too).
  if (cfg_.reorder_every > 0) reorder_slots(boundary_);
  init_boundary_weights();
  lists_valid_ = false;
}

// f(i) for every fluid particle, split statically over the fluid particles alone: boundary particles
// (often as many as the fluid, and stored after it) would otherwise leave one thread idle.
template <int Dim, class Real>
template <class F>
void Simulation<Dim, Real>::for_fluid(F&& f) const {
  for_each_of(fluid_, f);
}

template <int Dim, class Real>
template <class F>
void Simulation<Dim, Real>::for_each_of(const IndexList& set, F&& f) const {
  const std::uint32_t* idx = set.data();
  parallel_for(set.size(), [&](std::size_t k) { f(static_cast<std::size_t>(idx[k])); });
}

// Akinci et al. 2012: V_b = 1 / sum_k W_bk over boundary particles (self included), psi_b = rho0 V_b.
// Irregular sampling of a wall then still gives the same density contribution per unit area.
template <int Dim, class Real>
void Simulation<Dim, Real>::init_boundary_weights() {
  if (fluid_count_ == p_.size()) return;
  compute_neighbors(true);
  with_kernel<Dim, Real>(cfg_.density_kernel, cfg_.support, [&](const auto w) {
    parallel_for(p_.size(), [&](std::size_t b) {
      if (p_.kind[b] != kBoundary || p_.m[b] > 0) return;  // a weight given by the scene is kept
      Real s = w.W2(0);
      for (const auto* it = nl_.begin(b); it != nl_.end(b); ++it)
        if (p_.kind[*it] == kBoundary) s += w.W2(distance2(p_.x[b], p_.x[*it]));
      p_.m[b] = rho0_[b] / s;
    });
    // Dynamic walls: the wall-wall part of each wall's summation density, fixed for the run (weights
    // first: a neighbour's weight may have just been set above). Summed in row order (ascending).
    if (cfg_.wall_model != WallModel::Dynamic) return;
    wall_self_rho_.assign(p_.size(), Real(0));
    parallel_for(p_.size(), [&](std::size_t b) {
      if (p_.kind[b] != kBoundary) return;
      Real s = p_.m[b] * w.W2(0);
      for (const auto* it = nl_.begin(b); it != nl_.end(b); ++it)
        if (p_.kind[*it] == kBoundary) s += p_.m[*it] * w.W2(distance2(p_.x[b], p_.x[*it]));
      wall_self_rho_[b] = s;
    });
  });
}

// Cells of size h counted from the lowest corner of these particles, keyed in Z-order; equal keys by id.
// The order is a function of positions and ids alone (a total order, so any sort gives it), which
// keeps results independent of the neighbour method, the skin and the thread count. Particles move
// only among `slots`, so every slot keeps its kind.
template <int Dim, class Real>
void Simulation<Dim, Real>::reorder_slots(const IndexList& slots) {
  const std::size_t m = slots.size();
  if (m < 2) return;
  V lo = p_.x[slots[0]];
  for (const std::uint32_t i : slots)
    for (int a = 0; a < Dim; ++a) lo[a] = std::min(lo[a], p_.x[i][a]);
  const Real inv = Real(1) / cfg_.support;
  constexpr std::uint64_t cmax = (std::uint64_t{1} << (64 / Dim)) - 1;
  struct Item {
    std::uint64_t key;
    std::uint32_t id, slot;
  };
  std::vector<Item> items(m);
  parallel_for(m, [&](std::size_t k) {
    const std::uint32_t i = slots[k];
    std::uint64_t c[Dim];
    for (int a = 0; a < Dim; ++a) {
      // Finite positions (check_state) at or above lo; far cells are clamped (only the order suffers).
      const Real q = std::min(std::floor((p_.x[i][a] - lo[a]) * inv), static_cast<Real>(cmax));
      c[a] = std::min(static_cast<std::uint64_t>(q), cmax);
    }
    items[k] = {morton_key<Dim>(c), p_.id[i], i};
  });
  std::sort(items.begin(), items.end(),
            [](const Item& a, const Item& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
  // Slot slots[k] receives the particle from slot items[k].slot.
  auto permute = [&](auto& field) {
    if (field.size() != p_.size()) return;  // a scratch array not in use
    using T = typename std::remove_reference_t<decltype(field)>::value_type;
    std::vector<T> tmp(m);
    parallel_for(m, [&](std::size_t k) { tmp[k] = field[items[k].slot]; });
    parallel_for(m, [&](std::size_t k) { field[slots[k]] = tmp[k]; });
  };
  p_.for_each_field([&](std::string_view, auto& field) { permute(field); });
  // Every member array that persists between steps (the others are rebuilt before they are read).
  permute(rho0_);
  permute(search_h_);
  permute(vol_);
  permute(prho2_);
  permute(f_pressure_);
  permute(normal_);
  lists_valid_ = false;  // x_built_ and the lists name the old slots
}

template <int Dim, class Real>
void Simulation<Dim, Real>::compute_neighbors(bool boundary_rows) {
  // Boundary rows are never read by a step (j is a neighbour of i iff |x_i - x_j| <= h_i, so fluid rows
  // do not depend on the boundary's support).
  if (boundary_rows || search_h_.size() != p_.size()) {
    search_.build(std::span<const V>(p_.x), std::span<const Real>(p_.h));
    search_.find_all(nl_);
    lists_valid_ = false;
    return;
  }
  if (lists_valid_ && skin_ > 0) {
    Real d2 = 0;  // largest squared displacement since the lists were built (order-free: a maximum)
    const auto count = static_cast<std::int64_t>(fluid_.size());
#pragma omp parallel for schedule(static) reduction(max : d2)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::size_t i = fluid_[static_cast<std::size_t>(k)];
      d2 = std::max(d2, distance2(p_.x[i], x_built_[i]));
    }
    const Real limit = Real(0.45) * skin_;
    if (d2 <= limit * limit) return;
  }
  search_.build(std::span<const V>(p_.x), std::span<const Real>(search_h_));
  search_.find_all(nl_);
  if (skin_ > 0) x_built_ = p_.x;
  lists_valid_ = true;
  ++timings_.list_builds;
}

// The rows of `set` cut down to the pairs within h_i, in the same (ascending) order: every pair loop
// then runs without the skin test. That test is a branch taken for about a third of the candidates;
// once the particles are in cell order (reorder_every) its pattern along a sorted row is irregular, and
// the mispredictions cost more than this pass (which writes each candidate and advances by the test's
// outcome, without a branch). The test is the one the loops made before: the same pairs, the same bits.
template <int Dim, class Real>
void Simulation<Dim, Real>::filter_lists(const IndexList& set) {
  within_.resize(nl_.indices.size());
  within_count_.resize(p_.size());
  for_each_of(set, [&](std::size_t i) {
    const V xi = p_.x[i];
    const Real hi2 = p_.h[i] * p_.h[i];
    std::uint32_t* out = within_.data() + nl_.offsets[i];
    std::uint32_t c = 0;
    for (const auto* it = nl_.begin(i); it != nl_.end(i); ++it) {
      const std::uint32_t j = *it;
      out[c] = j;
      c += distance2(xi, p_.x[j]) <= hi2 ? 1u : 0u;
    }
    within_count_[i] = c;
  });
}

// Paper eq. 7 (or the number density of Solenthaler & Pajarola 2008), then the equation of state.
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_density_pressure(const IndexList& set) {
  timings_.density_evals += set.size();
  const bool number = cfg_.density == DensityFormulation::Number && cfg_.model == Model::PaperMultiphase;
  vol_.resize(p_.size());
  prho2_.resize(p_.size());
  with_kernel<Dim, Real>(cfg_.density_kernel, cfg_.support, [&](const auto w) {
    for_each_of(set, [&](std::size_t i) {
      const V xi = p_.x[i];
      Real rho = 0;
      if (number) {
        // Each neighbour counts by its volume, not its mass, so a light particle next to a heavy one
        // is not given the heavy one's density. A wall particle of volume V_b = psi_b / rho0_b counts as
        // V_b / V_i fluid particles (V_i = m_i / rho0_i), so that with one phase this is eq. 7 exactly.
        Real delta = w.W2(0);
        const Real inv_vol_i = rho0_[i] / p_.m[i];
        for (const auto* it = in_begin(i); it != in_end(i); ++it) {
          const std::uint32_t j = *it;
          const Real r2 = distance2(xi, p_.x[j]);
          const Real wij = w.W2(r2);
          delta += p_.kind[j] == kFluid ? wij : wij * (p_.m[j] / rho0_[j]) * inv_vol_i;
        }
        rho = p_.m[i] * delta;
      } else {
        rho = density_term(w, p_.m[i], Real(0));
        for (const auto* it = in_begin(i); it != in_end(i); ++it) {
          const Real r2 = distance2(xi, p_.x[*it]);
          rho += density_term(w, p_.m[*it], r2);
        }
      }
      p_.rho[i] = rho;
      const Real pres = cfg_.eos.pressure(rho, rho0_[i]);
      p_.p[i] = pres;
      vol_[i] = p_.m[i] / rho;
      prho2_[i] = pres / (rho * rho);
    });
  });
}

// Adami, Hu & Adams 2012, for walls at rest (a_w = 0):
//   p_w = (sum_f p_f W_wf + g . sum_f rho_f (x_w - x_f) W_wf) / sum_f W_wf       (their eq. 27)
//   rho_w = the density at which the equation of state gives p_w                 (their eq. 28)
//   v~_w = 2 v_w - sum_f v_f W_wf / sum_f W_wf = -(the kernel average)            (their eq. 22-23)
// over the fluid particles f within h_f of w. A step searches boundary particles with support 0 (they
// have no rows), so the wall's neighbours are gathered from the fluid rows: counted, placed, then each
// wall's list sorted, so every sum runs in ascending fluid index whatever the thread count or the
// neighbour method (the set is exactly {f : |x_w - x_f| <= h_f}, the pairs the force pass sees).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_wall_states() {
  const std::size_t n = p_.size();
  if (boundary_.empty()) return;
  wall_start_.assign(n + 1, 0);
  auto each_wall_pair = [&](auto&& visit) {
    for_fluid([&](std::size_t f) {
      for (const auto* it = in_begin(f); it != in_end(f); ++it) {  // filter_lists: within h_f
        const std::uint32_t b = *it;
        if (p_.kind[b] == kBoundary) visit(f, b);
      }
    });
  };
  each_wall_pair([&](std::size_t, std::uint32_t b) {
    std::atomic_ref<std::uint32_t>(wall_start_[b + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t i = 0; i < n; ++i) wall_start_[i + 1] += wall_start_[i];
  wall_nbr_.resize(wall_start_[n]);
  std::vector<std::uint32_t>& cursor = wall_cursor_;
  cursor.assign(wall_start_.begin(), wall_start_.end() - 1);
  each_wall_pair([&](std::size_t f, std::uint32_t b) {
    const std::uint32_t k = std::atomic_ref<std::uint32_t>(cursor[b]).fetch_add(1, std::memory_order_relaxed);
    wall_nbr_[k] = static_cast<std::uint32_t>(f);
  });
  wall_v_.resize(n);
  with_kernel<Dim, Real>(cfg_.density_kernel, cfg_.support, [&](const auto w) {
    for_each_of(boundary_, [&](std::size_t b) {
      std::uint32_t* first = wall_nbr_.data() + wall_start_[b];
      std::uint32_t* last = wall_nbr_.data() + wall_start_[b + 1];
      std::sort(first, last);
      if (cfg_.wall_model == WallModel::Dynamic) {
        // A fluid particle held at rest: summation density (its fixed wall part, then the fluid in
        // ascending index) and the fluid's EOS, never below 0: the outer layers lack neighbours beyond
        // them, and an unclamped EOS would make them pull the fluid in. Any p_w(rho_w) is the derivative
        // of a wall energy (here the clamped EOS's), so the forces stay conservative.
        Real rho = wall_self_rho_[b];
        for (const std::uint32_t* it = first; it != last; ++it)
          rho += density_term(w, p_.m[*it], distance2(p_.x[b], p_.x[*it]));
        const Real pw = std::max(Real(0), cfg_.eos.pressure(rho, rho0_[b]));
        p_.p[b] = pw;
        p_.rho[b] = rho;
        vol_[b] = p_.m[b] / rho;
        prho2_[b] = pw / (rho * rho);
        wall_v_[b] = p_.v[b];
        return;
      }
      Real wsum = 0, psum = 0;
      V rsum{}, vsum{};
      for (const std::uint32_t* it = first; it != last; ++it) {
        const std::uint32_t f = *it;
        const V xwf = p_.x[b] - p_.x[f];
        const Real wwf = w.W2(norm2(xwf));
        wsum += wwf;
        psum += p_.p[f] * wwf;
        rsum += xwf * (p_.rho[f] * wwf);
        vsum += p_.v[f] * wwf;
      }
      // A wall particle no fluid particle reaches is read by no force; it keeps rest values.
      Real pw = wsum > 0 ? (psum + dot(cfg_.gravity, rsum)) / wsum : Real(0);
      if (cfg_.eos.clamp_negative && pw < 0) pw = 0;
      const Real rhow = cfg_.eos.density(pw, rho0_[b]);
      p_.p[b] = pw;
      p_.rho[b] = rhow;
      vol_[b] = p_.m[b] / rhow;
      prho2_[b] = pw / (rhow * rhow);
      wall_v_[b] = wsum > 0 ? p_.v[b] * Real(2) - vsum / wsum : V{};
    });
  });
}

// CSF normals n_i = sum_j V_j (c_j - c_i) grad W_ij: the difference form vanishes exactly inside a phase.
// Walls take the colour of the fluid particle, so they contribute nothing.
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_normals(const IndexList& set) {
  timings_.normal_evals += set.size();
  const Poly6Kernel<Dim, Real> wc(cfg_.support);
  // Akinci 2013: the full colour gradient h sum_j V_j grad W_ij (non-zero at a free surface).
  const bool full = cfg_.tension == TensionModel::Akinci;
  normal_.assign(p_.size(), V{});
  for_each_of(set, [&](std::size_t i) {
    V n{};
    for (const auto* it = in_begin(i); it != in_end(i); ++it) {
      const std::uint32_t j = *it;
      if (p_.kind[j] != kFluid) continue;
      n += wc.gradW(p_.x[i] - p_.x[j]) *
           (full ? p_.m[j] / p_.rho[j] : p_.m[j] / p_.rho[j] * (p_.color[j] - p_.color[i]));
    }
    normal_[i] = full ? n * p_.h[i] : n;
  });
}

// Algorithm 1, lines 2-15: f_i = m_i g + eq. 8a + eq. 8b + eq. 9 (or CSF).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_forces_paper(const IndexList& set, const IndexList& normal_set) {
  timings_.force_evals += set.size();
  const Poly6Kernel<Dim, Real> wc(cfg_.support);
  const ViscosityKernel<Dim, Real> wv(cfg_.support);
  const Real lap_self = wc.laplacian(0);
  const bool csf = any_tension_ && cfg_.tension == TensionModel::Csf;
  const bool akinci = any_tension_ && cfg_.tension == TensionModel::Akinci;
  const bool eq9 = any_tension_ && cfg_.tension == TensionModel::Paper;
  const Real thr2 = cfg_.tension_threshold * cfg_.tension_threshold;
  const CohesionKernel<Dim, Real> coh(cfg_.support);
  if (csf || akinci) compute_normals(normal_set);
  with_kernel<Dim, Real>(cfg_.pressure_kernel, cfg_.support, [&](const auto wp) {
    for_each_of(set, [&](std::size_t i) {
      const Real vol_i = p_.m[i] / p_.rho[i];
      V f = cfg_.gravity * p_.m[i];
      // The colour field includes particle i itself (its Laplacian does not vanish at r = 0), so that it
      // is ~0 inside a uniform phase.
      ColorField<Dim, Real> cf;
      cf.lap = vol_i * p_.color[i] * lap_self;
      PairInput<Dim, Real> in{};
      in.mi = p_.m[i];
      in.rhoi = p_.rho[i];
      in.pi = p_.p[i];
      in.mui = p_.mu[i];
      const bool csf_i = csf && norm2(normal_[i]) > thr2 && norm2(normal_[i]) > 0;
      const V nhat_i = csf_i ? normal_[i] / norm(normal_[i]) : V{};
      // CSF: kappa = -div(n / |n|) over neighbours with a defined normal, divided by their kernel sum
      // (Morris 2000): the sum alone takes n_j = n_i for the others (more than one support from the
      // interface) and underestimated the curvature by 17% (Laplace jump) whatever the resolution.
      Real kappa = 0, wsum = vol_i * wc.W2(0);
      const V vel_i = p_.v[i];
      for (const auto* it = in_begin(i); it != in_end(i); ++it) {
        const std::uint32_t j = *it;
        in.xij = p_.x[i] - p_.x[j];
        in.r = norm(in.xij);
        if (p_.kind[j] == kFluid) {
          // averaged_pressure_force and averaged_viscosity_force (eq. 8a, 8b), inlined with the
          // per-particle volumes of the density pass (same expressions, same order).
          const Real vv = -vol_i * vol_[j];
          f += wp.gradW(in.xij) * (vv * (in.pi + p_.p[j]) / 2);
          f += (vel_i - p_.v[j]) * (vv * (in.mui + p_.mu[j]) / 2 * wv.laplacian(in.r));
          if (csf_i && norm2(normal_[j]) > thr2 && norm2(normal_[j]) > 0) {
            const V nhat_j = normal_[j] / norm(normal_[j]);
            kappa -= vol_[j] * dot(nhat_j - nhat_i, wc.gradW(in.xij));
            wsum += vol_[j] * wc.W2(in.r * in.r);
          } else if (eq9) {
            accumulate_color(cf, in.xij, in.r, vol_[j], p_.color[j], wc);
          } else if (akinci && p_.phase[j] == p_.phase[i] && in.r > 0) {
            // Each factor is symmetric in (i, j) and x_ij, n_i - n_j antisymmetric: the pair's forces
            // on i and j are exact opposites.
            const auto& ph = cfg_.phases[static_cast<std::size_t>(p_.phase[i])];
            const Real k = (rho0_[i] + rho0_[j]) / (in.rhoi + p_.rho[j]);
            f += (in.xij * (-ph.sigma * in.mi * p_.m[j] * coh.C(in.r) / in.r) +
                  (normal_[i] - normal_[j]) * (-ph.sigma * (in.mi + p_.m[j]) / 2)) *
                 k;
          }
        } else {
          // A boundary particle acts as fluid with i's density (mirrored, so that its volume psi_b / rho_i
          // matches how i sees fluid neighbours; with rho0 instead a resting fluid is pushed off the
          // walls), i's pressure extrapolated to it (see mirrored_boundary_pressure) and i's colour (walls
          // are neutral to interface tension). No slip: eq. 8b against a particle at rest with i's mu.
          in.mj = p_.m[j];
          if (wall_states_) {
            // Adami: eq. 8a and 8b as between two fluid particles, with the wall's own pressure and
            // volume psi_b / rho_w (compute_wall_states) and its extrapolated velocity; i's mu.
            const Real vv = -vol_i * vol_[j];
            f += wp.gradW(in.xij) * (vv * (in.pi + p_.p[j]) / 2);
            if (cfg_.no_slip) f += (vel_i - wall_v_[j]) * (vv * in.mui * wv.laplacian(in.r));
          } else {
            in.rhoj = in.rhoi;
            in.pj = mirrored_boundary_pressure(in.pi, in.rhoi, cfg_.gravity, in.xij);
            if (cfg_.eos.clamp_negative && in.pj < 0) in.pj = 0;
            f += averaged_pressure_force(in, wp);
            if (cfg_.no_slip) f += vel_i * (-vol_i * (in.mj / in.rhoi) * in.mui * wv.laplacian(in.r));
          }
          if (eq9) accumulate_color(cf, in.xij, in.r, p_.m[j] / in.rhoi, p_.color[i], wc);
        }
      }
      if (csf_i) {
        const auto& ph = cfg_.phases[static_cast<std::size_t>(p_.phase[i])];
        f += normal_[i] * (ph.sigma * kappa / wsum * vol_i);
      } else if (eq9) {
        // Eq. 9 has the units of a force density (sigma [N/m] times a curvature of C [1/m^2]); by the
        // paper's own eq. 6 the particle's force is V_i times it. Taken literally as a force it gives
        // accelerations ~1e5 m/s^2 for the paper's sigma, m and h.
        const auto& ph = cfg_.phases[static_cast<std::size_t>(p_.phase[i])];
        f += interface_tension_force(cf, ph.sigma, cfg_.tension_threshold) * vol_i;
      }
      p_.f[i] = f;
    });
  });
}

// The write-up's loop: non-pressure forces (Monaghan viscosity, gravity, Mueller surface tension) and the
// symmetric pressure force, kept apart so that the integrator can apply them in two sub-steps.
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_forces_wcsph() {
  const Poly6Kernel<Dim, Real> wc(cfg_.support);
  const Real lap_self = wc.laplacian(0);
  const Real h = cfg_.support;
  const Real eps2 = Real(0.01) * h * h;     // Monaghan's r^2 regulariser
  const Real visc_c = Real(2 * (Dim + 2));  // 2 (d + 2)
  timings_.force_evals += fluid_.size();
  with_kernel<Dim, Real>(cfg_.pressure_kernel, cfg_.support, [&](const auto wg) {
    for_fluid([&](std::size_t i) {
      const Real vol_i = p_.m[i] / p_.rho[i];
      V fnp = cfg_.gravity * p_.m[i];
      V fp{};
      ColorField<Dim, Real> cf;
      cf.lap = vol_i * lap_self;
      PairInput<Dim, Real> in{};
      in.mi = p_.m[i];
      in.rhoi = p_.rho[i];
      in.pi = p_.p[i];
      in.mui = p_.mu[i];
      const V vel_i = p_.v[i];
      const Real prho2_i = prho2_[i];
      for (const auto* it = in_begin(i); it != in_end(i); ++it) {
        const std::uint32_t j = *it;
        in.xij = p_.x[i] - p_.x[j];
        in.r = norm(in.xij);
        if (p_.kind[j] == kFluid) {
          // monaghan_viscosity_force and symmetric_pressure_force, inlined with one kernel gradient
          // and the per-particle quotients of the density pass (same expressions, same order).
          const V g = wg.gradW(in.xij);
          const Real q = dot(vel_i - p_.v[j], in.xij) / (in.r * in.r + eps2);
          fnp += g * (visc_c * (in.mui + p_.mu[j]) / 2 * vol_i * vol_[j] * q);
          fp += g * (-in.mi * p_.m[j] * (prho2_i + prho2_[j]));
          if (any_tension_) accumulate_color(cf, in.xij, in.r, vol_[j], Real(1), wc);
        } else if (wall_states_) {
          // Adami: the fluid pair terms with the wall's pressure, density and extrapolated velocity
          // (compute_wall_states); the viscosity takes i's mu.
          const V g = wg.gradW(in.xij);
          fp += g * (-in.mi * p_.m[j] * (prho2_i + prho2_[j]));
          if (cfg_.no_slip) {
            const Real q = dot(vel_i - wall_v_[j], in.xij) / (in.r * in.r + eps2);
            fnp += g * (visc_c * in.mui * vol_i * vol_[j] * q);
          }
          if (any_tension_) accumulate_color(cf, in.xij, in.r, p_.m[j] / in.rhoi, Real(1), wc);
        } else {
          Real pb = mirrored_boundary_pressure(in.pi, in.rhoi, cfg_.gravity, in.xij);
          if (cfg_.eos.clamp_negative && pb < 0) pb = 0;
          const V g = wg.gradW(in.xij);  // shared by the pressure and the no-slip term
          fp += boundary_pressure_force(g, in.mi, in.rhoi, in.pi, pb, p_.m[j]);
          if (cfg_.no_slip) {
            // Monaghan's operator against a particle at rest with volume psi_b / rho_i and i's mu.
            const Real q = dot(vel_i, in.xij) / (in.r * in.r + eps2);
            fnp += g * (visc_c * in.mui * vol_i * (p_.m[j] / in.rhoi) * q);
          }
          if (any_tension_) accumulate_color(cf, in.xij, in.r, p_.m[j] / in.rhoi, Real(1), wc);
        }
      }
      if (any_tension_) {
        // Mueller 2003 gives a force density; the particle's share is V_i times it.
        const auto& ph = cfg_.phases[static_cast<std::size_t>(p_.phase[i])];
        fnp += interface_tension_force(cf, ph.sigma, cfg_.tension_threshold) * vol_i;
      }
      p_.f[i] = fnp;
      f_pressure_[i] = fp;
    });
  });
}

// Fixed, or the global Courant step: eq. 12 (alpha h / c and alpha h / |v|), the viscous limit
// viscous * h^2 / nu and the force limit force * sqrt(h / |a|), capped at dt_max.
template <int Dim, class Real>
Real Simulation<Dim, Real>::choose_dt() const {
  if (cfg_.time.mode == TimeStepping::Fixed) return cfg_.time.dt;
  const Real h = cfg_.support;
  const Real alpha = cfg_.time.courant;
  Real dt = cfg_.time.dt_max;
  Real rho0_min = std::numeric_limits<Real>::max(), nu_max = 0;
  for (const auto& ph : cfg_.phases) {
    rho0_min = std::min(rho0_min, ph.rest_density);
    nu_max = std::max(nu_max, ph.viscosity / ph.rest_density);
  }
  dt = std::min(dt, alpha * h / cfg_.eos.sound_speed(rho0_min));
  if (nu_max > 0) dt = std::min(dt, cfg_.time.viscous * h * h / nu_max);
  Real v2 = 0, a2 = 0;
  const bool wcsph = cfg_.model == Model::Wcsph;
  // A maximum does not depend on the order of evaluation: parallel and still deterministic.
  const auto count = static_cast<std::int64_t>(fluid_.size());
#pragma omp parallel for schedule(static) reduction(max : v2, a2)
  for (std::int64_t k = 0; k < count; ++k) {
    const std::size_t i = fluid_[static_cast<std::size_t>(k)];
    v2 = std::max(v2, norm2(p_.v[i]));
    const V f = wcsph ? p_.f[i] + f_pressure_[i] : p_.f[i];
    a2 = std::max(a2, norm2(f) / (p_.m[i] * p_.m[i]));
  }
  if (v2 > 0) dt = std::min(dt, alpha * h / std::sqrt(v2));
  if (a2 > 0) dt = std::min(dt, cfg_.time.force * std::sqrt(h / std::sqrt(a2)));
  return dt;
}

// Leap-frog (eq. 11). On the first step v(t0) becomes v(t0 - dt/2) = v(t0) - dt/2 a(t0), so that the
// kick below lands on v(t0 + dt/2). With a changing step the kick uses the mean of the old and new step,
// which keeps the velocity at the midpoints of the position steps.
template <int Dim, class Real>
void Simulation<Dim, Real>::integrate_paper(Real dt) {
  const Real kick = leapfrog_started_ ? (last_dt_ + dt) / 2 : dt / 2;
  for_fluid([&](std::size_t i) {
    p_.v[i] += p_.f[i] * (kick / p_.m[i]);
    p_.x[i] += p_.v[i] * dt;
  });
  leapfrog_started_ = true;
}

// The write-up's split: v* = v + dt (F_visc + F_ext)/m, then v(t+dt) = v* + dt F_press/m,
// x(t+dt) = x + dt v(t+dt) (symplectic Euler).
template <int Dim, class Real>
void Simulation<Dim, Real>::integrate_wcsph(Real dt) {
  for_fluid([&](std::size_t i) {
    const V vstar = p_.v[i] + p_.f[i] * (dt / p_.m[i]);
    p_.v[i] = vstar + f_pressure_[i] * (dt / p_.m[i]);
    p_.x[i] += p_.v[i] * dt;
    p_.f[i] += f_pressure_[i];  // the total force, for output and the force limit of the next step
  });
}

template <int Dim, class Real>
void Simulation<Dim, Real>::apply_walls() {
  if (!cfg_.box.enabled && cfg_.planes.empty()) return;
  for_fluid([&](std::size_t i) {
    if (cfg_.box.enabled)
      box_collision(p_.x[i], p_.v[i], cfg_.box.lo, cfg_.box.hi, cfg_.box.radius, cfg_.box.damping);
    for (const auto& pl : cfg_.planes)
      plane_collision(p_.x[i], p_.v[i], pl.normal, pl.offset, cfg_.restitution, cfg_.friction);
  });
}

// After each step: the first particle (lowest index) with a non-finite quantity or outside the domain
// stops the run with a diagnosis.
template <int Dim, class Real>
void Simulation<Dim, Real>::check_state() const {
  V lo{}, hi{};
  bool escape = false;
  if (cfg_.domain_set) {
    lo = cfg_.domain_lo;
    hi = cfg_.domain_hi;
    escape = true;
  } else if (cfg_.box.enabled) {
    lo = cfg_.box.lo;
    hi = cfg_.box.hi;
    escape = true;
  }
  const Real margin = cfg_.support;
  auto bad = [&](std::size_t i) {
    if (!all_finite(p_.x[i]) || !all_finite(p_.v[i]) || !all_finite(p_.f[i])) return true;
    if (!std::isfinite(p_.rho[i]) || !std::isfinite(p_.p[i])) return true;
    if (escape)
      for (int a = 0; a < Dim; ++a)
        if (p_.x[i][a] < lo[a] - margin || p_.x[i][a] > hi[a] + margin) return true;
    return false;
  };
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
  const auto count = static_cast<std::int64_t>(fluid_.size());
#pragma omp parallel for schedule(static) reduction(min : first)
  for (std::int64_t k = 0; k < count; ++k) {
    const std::uint32_t i = fluid_[static_cast<std::size_t>(k)];
    if (bad(i)) first = std::min(first, static_cast<std::int64_t>(i));
  }
  if (first == std::numeric_limits<std::int64_t>::max()) return;

  const auto i = static_cast<std::size_t>(first);
  std::ostringstream os;
  os.precision(9);
  os << "simulation unstable at step " << steps_ + 1 << " (t = " << time_ << " s): particle " << i << " (id "
     << p_.id[i] << "): ";
  auto vec = [&](const char* name, const V& v) {
    os << name << " = (";
    for (int a = 0; a < Dim; ++a) os << (a ? ", " : "") << v[a];
    os << ")";
  };
  if (!all_finite(p_.x[i]))
    vec("position", p_.x[i]);
  else if (!all_finite(p_.v[i]))
    vec("velocity", p_.v[i]);
  else if (!all_finite(p_.f[i]))
    vec("force", p_.f[i]);
  else if (!std::isfinite(p_.rho[i]))
    os << "density = " << p_.rho[i];
  else if (!std::isfinite(p_.p[i]))
    os << "pressure = " << p_.p[i];
  else {
    vec("position", p_.x[i]);
    os << " left the domain";
    vec(" [lo", lo);
    vec(", hi", hi);
    os << "] (margin " << margin << " m)";
  }
  throw SimulationError(os.str());
}

// Eq. 12 for one particle, with the same viscous and force limits as the global step.
template <int Dim, class Real>
Real Simulation<Dim, Real>::particle_dt(std::size_t i) const {
  const Real h = cfg_.support, alpha = cfg_.time.courant;
  const auto& ph = cfg_.phases[static_cast<std::size_t>(p_.phase[i])];
  Real dt = std::min(cfg_.time.dt_max, alpha * h / cfg_.eos.sound_speed(ph.rest_density));
  if (ph.viscosity > 0) dt = std::min(dt, cfg_.time.viscous * h * h * ph.rest_density / ph.viscosity);
  const Real v = norm(p_.v[i]);
  if (v > 0) dt = std::min(dt, alpha * h / v);
  const Real a = norm(p_.f[i]) / p_.m[i];
  if (a > 0) dt = std::min(dt, cfg_.time.force * std::sqrt(h / a));
  return dt;
}

// Per-particle steps: the forces of a due particle i read, for every fluid neighbour j within h_i, its
// density, pressure and volume (eq. 8a-c) and, with CSF, its normal, which reads the densities of j's own
// neighbours. Densities are therefore needed on due + N(due) (+ N(N(due)) with CSF), normals on
// due + N(due); anything more would be computed and never read. Marks only ever set bits, so the sets do
// not depend on the order in which threads mark them.
template <int Dim, class Real>
void Simulation<Dim, Real>::build_work_sets() {
  // CSF and Akinci read the normals of neighbours, which read the densities of theirs.
  const bool csf =
      any_tension_ && (cfg_.tension == TensionModel::Csf || cfg_.tension == TensionModel::Akinci);
  // When every particle is due (often: a uniform limit such as alpha h / c binds them all), the sets are
  // the whole fluid and the marking pass would be pure overhead.
  if (full_passes_ || due_list_.size() == fluid_.size()) {
    rho_set_ = fluid_;
    normal_set_ = csf ? fluid_ : IndexList{};
    return;
  }
  constexpr std::uint8_t kRho = 1, kNormal = 2;
  mark_.assign(p_.size(), 0);
  auto mark_around = [&](const IndexList& from, std::uint8_t bits) {
    for_each_of(from, [&](std::size_t i) {
      std::atomic_ref<std::uint8_t>(mark_[i]).fetch_or(bits, std::memory_order_relaxed);
      const V xi = p_.x[i];
      const Real hi2 = p_.h[i] * p_.h[i];
      for (const auto* it = nl_.begin(i); it != nl_.end(i); ++it) {
        const std::uint32_t j = *it;
        if (p_.kind[j] != kFluid || distance2(xi, p_.x[j]) > hi2) continue;  // the passes' own test
        std::atomic_ref<std::uint8_t>(mark_[j]).fetch_or(bits, std::memory_order_relaxed);
      }
    });
  };
  auto collect = [&](IndexList& out, std::uint8_t bit) {
    out.clear();
    for (const std::uint32_t i : fluid_)
      if (mark_[i] & bit) out.push_back(i);
  };
  if (csf) {
    mark_around(due_list_, static_cast<std::uint8_t>(kRho | kNormal));
    collect(normal_set_, kNormal);
    mark_around(normal_set_, kRho);
  } else {
    mark_around(due_list_, kRho);
    normal_set_.clear();
  }
  collect(rho_set_, kRho);
}

// Per-particle power-of-two steps (Desbrun 1996; paper eq. 12-13). Times are integer ticks of
// dt_max / 2^max_level, so "is particle i due" is an exact comparison. Each step:
//  1. the global clock T is the smallest particle time; particles with tick == T are due;
//  2. every position is extrapolated to T (x_j + (T - t_j) v_j) and the neighbour lists kept up to date
//     for all; forces are evaluated for the due particles only, densities (and CSF normals) only where
//     those forces read them (build_work_sets), so a sub-step costs in proportion to the particles it
//     advances;
//  3. a due particle picks its level from eq. 12 (coarsening only onto a multiple of the coarser step),
//     gets the position correction of a step change, then the leap-frog kick and drift of Algorithm 1.
// Step change: the stored v = v(t - dt_old/2) must become v(t + dt_new/2) = v + a (dt_old + dt_new)/2
// (Exact). Algorithm 1's kick v += a dt_new leaves the velocity off by a (dt_new - dt_old)/2, and a position
// correction alone (eq. 13) cannot undo a velocity error that persists in all later steps; eq. 13 as
// printed is offered as Printed, and the single-particle test measures its error.
template <int Dim, class Real>
void Simulation<Dim, Real>::step_per_particle() {
  const int L = cfg_.time.max_level;
  const Real unit = cfg_.time.dt_max / static_cast<Real>(std::int64_t{1} << L);
  std::int64_t T = std::numeric_limits<std::int64_t>::max();
  for (const std::uint32_t i : fluid_) T = std::min(T, p_.tick[i]);
  if (T == std::numeric_limits<std::int64_t>::max()) T = 0;

  Stopwatch sw;
  // Reorder on the clock, at multiples of reorder_every * dt_max: particles' steps are aligned to
  // multiples of themselves, so there every particle is due (synchronised), and the schedule is a
  // function of the ticks (checkpointed) alone.
  const std::int64_t period = static_cast<std::int64_t>(cfg_.reorder_every) << L;
  if (period > 0 && T % period == 0) {
    reorder_slots(fluid_);
    ++timings_.reorders;
    timings_.reorder += sw.ms();
    sw.reset();
  }
  due_list_.clear();
  xs_ = p_.x;
  for (const std::uint32_t i : fluid_) {
    if (p_.tick[i] == T)
      due_list_.push_back(i);
    else
      xs_[i] += p_.v[i] * (static_cast<Real>(T - p_.tick[i]) * unit);
  }
  std::swap(p_.x, xs_);  // the force passes see positions at time T
  compute_neighbors();
  timings_.neighbors += sw.ms();
  sw.reset();
  build_work_sets();
  filter_lists(rho_set_);  // every pass below reads rows of rho_set_ only (it holds the other sets)
  compute_density_pressure(rho_set_);
  compute_forces_paper(due_list_, normal_set_);
  std::swap(p_.x, xs_);
  timings_.forces += sw.ms();

  sw.reset();
  const bool started = leapfrog_started_;
  const auto corr = cfg_.time.correction;
  for_each_of(due_list_, [&](std::size_t i) {
    int level = 0;
    const Real want = particle_dt(i);
    while (level < L && cfg_.time.dt_max / static_cast<Real>(std::int64_t{1} << level) > want) ++level;
    const int old = p_.level[i];
    // A coarser step must start on a multiple of itself, so that particles stay synchronised.
    while (level < old && T % (std::int64_t{1} << (L - level)) != 0) ++level;
    const Real dt_new = static_cast<Real>(std::int64_t{1} << (L - level)) * unit;
    const Real dt_old = static_cast<Real>(std::int64_t{1} << (L - old)) * unit;
    const V a = p_.f[i] / p_.m[i];
    if (!started) {
      p_.v[i] += a * (dt_new / 2);  // from v(t0) straight to v(t0 + dt/2) (eq. 11 initialisation)
    } else if (corr == StepChangeCorrection::Exact) {
      p_.v[i] += a * ((dt_old + dt_new) / 2);
    } else {
      if (level != old) p_.x[i] += a * ((dt_new * dt_new - dt_old * dt_old) / 8);
      p_.v[i] += a * dt_new;
    }
    p_.x[i] += p_.v[i] * dt_new;
    p_.level[i] = level;
    p_.tick[i] = T + (std::int64_t{1} << (L - level));
  });
  leapfrog_started_ = true;
  apply_walls();
  check_state();
  std::int64_t next = std::numeric_limits<std::int64_t>::max();
  for (const std::uint32_t i : fluid_) next = std::min(next, p_.tick[i]);
  if (next == std::numeric_limits<std::int64_t>::max()) next = T + (std::int64_t{1} << L);
  last_dt_ = static_cast<Real>(next - T) * unit;
  time_ = static_cast<Real>(next) * unit;
  ++steps_;
  timings_.integration += sw.ms();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::step() {
  if (cfg_.time.mode == TimeStepping::PerParticle) {
    step_per_particle();
    return;
  }
  Stopwatch sw;
  // On the step count alone (checkpointed), never on the list rebuilds: see the header.
  if (cfg_.reorder_every > 0 && steps_ % cfg_.reorder_every == 0) {
    reorder_slots(fluid_);
    ++timings_.reorders;
    timings_.reorder += sw.ms();
    sw.reset();
  }
  compute_neighbors();
  timings_.neighbors += sw.ms();

  sw.reset();
  filter_lists(fluid_);
  compute_density_pressure(fluid_);
  if (wall_states_) compute_wall_states();
  if (cfg_.model == Model::PaperMultiphase)
    compute_forces_paper(fluid_, fluid_);
  else
    compute_forces_wcsph();
  timings_.forces += sw.ms();

  sw.reset();
  const Real dt = choose_dt();
  if (cfg_.model == Model::PaperMultiphase)
    integrate_paper(dt);
  else
    integrate_wcsph(dt);
  apply_walls();
  check_state();
  time_ += dt;
  last_dt_ = dt;
  ++steps_;
  timings_.integration += sw.ms();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::run_until(Real t_end) {
  while (time_ < t_end) step();
}

template <int Dim, class Real>
auto Simulation<Dim, Real>::momentum() const -> V {
  V s{};
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.v[i] * p_.m[i];
  return s;
}

template <int Dim, class Real>
Real Simulation<Dim, Real>::kinetic_energy() const {
  Real s = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.m[i] * norm2(p_.v[i]) / 2;
  return s;
}

template <int Dim, class Real>
Real Simulation<Dim, Real>::total_mass() const {
  Real s = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.m[i];
  return s;
}

template <int Dim, class Real>
void Simulation<Dim, Real>::restore(Particles<Dim, Real> particles, const IntegratorState<Real>& state,
                                    const std::string& source) {
  const std::size_t n = particles.size();
  if (n != p_.size()) {
    throw InputError(source + ": holds " + std::to_string(n) + " particles, the scene has " +
                     std::to_string(p_.size()));
  }
  if (particles.id.size() != n) {
    throw InputError(source + ": holds " + std::to_string(particles.id.size()) + " particle ids for " +
                     std::to_string(n) + " particles");
  }
  if (const auto err = id_permutation_error(particles.id); !err.empty())
    throw InputError(source + ": " + err);
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.phase[i] < 0 || static_cast<std::size_t>(particles.phase[i]) >= cfg_.phases.size() ||
        particles.kind[i] > kBoundary) {
      throw InputError(source + ": particle " + std::to_string(i) + " has phase " +
                       std::to_string(particles.phase[i]) + " / kind " +
                       std::to_string(int(particles.kind[i])) + ", not in this scene's tables");
    }
  }
  // Values no run holds (a checkpoint from another writer, or edited with its checksum fixed): refused
  // here, where the step would meet them as an internal error or undefined behaviour (non-finite
  // coordinates in the neighbour search, a shift by a level outside 0..max_level, ticks that overflow).
  particles.for_each_field([&](std::string_view name, const auto& field) {
    using T = typename std::remove_cvref_t<decltype(field)>::value_type;
    for (std::size_t i = 0; i < field.size(); ++i) {
      bool finite = true;
      if constexpr (std::is_same_v<T, Real>) {
        finite = std::isfinite(field[i]);
      } else if constexpr (std::is_same_v<T, V>) {
        for (int a = 0; a < Dim; ++a) finite = finite && std::isfinite(field[i][a]);
      }
      if (!finite)
        throw InputError(source + ": particle " + std::to_string(i) + " has a non-finite " +
                         std::string(name));
    }
  });
  if (!(std::isfinite(state.time) && state.time >= 0 && std::isfinite(state.last_dt) && state.last_dt >= 0))
    throw InputError(source + ": simulated time " + std::to_string(state.time) + " / last step " +
                     std::to_string(state.last_dt) + " is not a finite number >= 0");
  // Every particle's support is the scene's (set at construction, never changed), and per-particle steps
  // keep every fluid particle's tick within 2^max_level of the earliest (a due particle moves at most
  // dt_max ahead), so no step extrapolates a position further than dt_max.
  const std::int64_t max_tick = std::int64_t{1} << 62, spread = std::int64_t{1} << cfg_.time.max_level;
  std::int64_t lo_tick = max_tick, hi_tick = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.h[i] != cfg_.support)
      throw InputError(source + ": particle " + std::to_string(i) + " has support " +
                       std::to_string(particles.h[i]) + ", the scene's is " + std::to_string(cfg_.support));
    if (particles.level[i] < 0 || particles.level[i] > cfg_.time.max_level || particles.tick[i] < 0 ||
        particles.tick[i] > max_tick)
      throw InputError(source + ": particle " + std::to_string(i) + " has time-step level " +
                       std::to_string(particles.level[i]) + " / tick " + std::to_string(particles.tick[i]) +
                       ", outside 0.." + std::to_string(cfg_.time.max_level) + " / 0..2^62");
    if (particles.kind[i] == kFluid) {
      lo_tick = std::min(lo_tick, particles.tick[i]);
      hi_tick = std::max(hi_tick, particles.tick[i]);
    }
  }
  if (hi_tick > lo_tick && hi_tick - lo_tick > spread)
    throw InputError(source + ": fluid particles' ticks span " + std::to_string(lo_tick) + ".." +
                     std::to_string(hi_tick) + ", more than 2^" + std::to_string(cfg_.time.max_level) +
                     " (one largest step)");
  p_ = std::move(particles);
  fluid_.clear();
  boundary_.clear();
  for (std::size_t i = 0; i < p_.size(); ++i) {
    rho0_[i] = cfg_.phases[static_cast<std::size_t>(p_.phase[i])].rest_density;
    const bool fluid = p_.kind[i] == kFluid;
    (fluid ? fluid_ : boundary_).push_back(static_cast<std::uint32_t>(i));
    search_h_[i] = fluid ? p_.h[i] + skin_ : Real(0);
  }
  fluid_count_ = fluid_.size();
  lists_valid_ = false;
  // Dynamic walls: their fixed density share, from the restored walls (kept weights, no reorder). Its
  // neighbour search is the first to see the positions: one beyond what a search can index (1e86 m) is
  // the file's fault, named as such (the Simulation is then not usable; the caller stops).
  if (cfg_.wall_model == WallModel::Dynamic) {
    try {
      init_boundary_weights();
    } catch (const CapacityError& e) {
      throw InputError(source + ": " + e.what());
    }
  }
  time_ = state.time;
  last_dt_ = state.last_dt;
  steps_ = state.steps;
  leapfrog_started_ = state.leapfrog_started;
}

template class Simulation<2, float>;
template class Simulation<2, double>;
template class Simulation<3, float>;
template class Simulation<3, double>;

}  // namespace cellsph
