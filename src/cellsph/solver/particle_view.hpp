#pragma once
// What a per-particle pass sees: plain pointers to the particle arrays (Particles and the solver's own
// per-particle arrays) and to the neighbour rows, with the counts. A pass is a small functor or function
// marked CELLSPH_HD that takes this view (by value) and an index i and computes particle i's result; the
// driver (pass_driver.hpp) runs it over a set of indices. The view owns nothing and holds no container,
// so the same pass can later run on a device over device pointers.
#include <cstddef>
#include <cstdint>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

// One phase as the passes need it (the scene's Phase without its name).
template <class Real>
struct PhaseParams {
  Real rest_density;
  Real viscosity;  // dynamic viscosity mu [Pa s]
  Real sigma;      // interface tension coefficient
};

template <int Dim, class Real>
struct ParticleView {
  using V = Vec<Dim, Real>;
  static constexpr std::uint8_t kFluid = 0;     // ParticleKind::Fluid
  static constexpr std::uint8_t kBoundary = 1;  // ParticleKind::Boundary

  std::size_t n = 0;  // particles (fluid and boundary)

  // Particles<Dim, Real> (particles.hpp).
  V* x = nullptr;
  V* v = nullptr;
  V* f = nullptr;
  Real* m = nullptr;
  Real* rho = nullptr;
  Real* p = nullptr;
  Real* h = nullptr;
  Real* color = nullptr;
  Real* mu = nullptr;
  const std::int32_t* phase = nullptr;
  std::int32_t* level = nullptr;
  std::int64_t* tick = nullptr;
  const std::uint8_t* kind = nullptr;
  const std::uint32_t* id = nullptr;

  // The solver's per-particle arrays (Simulation members of the same names).
  const Real* rho0 = nullptr;     // rest density (from the phase)
  Real* vol = nullptr;            // V_j = m_j / rho_j, from the density pass
  Real* prho2 = nullptr;          // p_j / rho_j^2, from the density pass
  V* normal = nullptr;            // CSF / Akinci 2013 colour normal
  V* f_pressure = nullptr;        // WCSPH: pressure force, applied after the predicted velocity
  V* wall_v = nullptr;            // Adami: extrapolated no-slip velocity of a wall particle
  const V* wall_a = nullptr;      // moving walls (boundary/wall_motion.hpp): acceleration; null: all at rest
  Real* wall_self_rho = nullptr;  // dynamic walls: the fixed wall-wall part of the density
  Real* drho = nullptr;           // WCSPH continuity density: d rho / dt of this step
  // Volume-map walls (boundary/bender2019.hpp), per fluid particle, null without them: the walls' part
  // of the density and of its gradient, the equivalent wall particle's weight and x_i - x_b, and the
  // particles the solids replace in the support, and rho0 T g (the hydrostatic wall pressure's term).
  Real* vm_rho = nullptr;
  V* vm_g = nullptr;
  Real* vm_w = nullptr;
  V* vm_x = nullptr;
  Real* vm_count = nullptr;
  V* vm_h = nullptr;
  Real* df_alpha = nullptr;    // DFSPH (models/dfsph.hpp): 1 / (the factor's denominator)
  Real* df_kappa = nullptr;    // DFSPH: this sweep's pressure / rho^2 increment
  Real* df_kappa_v = nullptr;  // DFSPH: the divergence solve's pressure / rho^2 (warm start)
  V* df_grad = nullptr;        // DFSPH: grad W_ij of each pair of the rows, at the pair's slot in `within`
  V* df_gsum = nullptr;        // DFSPH: sum_j w_ij grad W_ij of the step (the density pass)
  V* df_gwall = nullptr;       // DFSPH: its walls' part, sum_b w_ib grad W_ib
  V* df_mv = nullptr;          // DFSPH: w_j v_j (the mass density's sweeps gather it)
  Real* df_mk = nullptr;       // DFSPH: m_j k_j of the sweep, 0 for a wall
  V* cg_v0 = nullptr;          // DFSPH's CG density solve (models/dfsph_cg.hpp): v before the kick by p
  Real* cg_s = nullptr;        // DFSPH CG: the predicted density error s_i (signed)
  Real* cg_p = nullptr;        // DFSPH CG: the search direction
  Real* cg_ap = nullptr;       // DFSPH CG: (A p)_i
  std::uint8_t* cg_active = nullptr;  // DFSPH CG: 1 in the active set

  // Neighbour rows. The Verlet lists (within h + skin): candidates + offsets[i] .. candidates + offsets[i +
  // 1]. The rows cut to h (filter_rows): within + offsets[i], within_count[i] long; the pair passes read
  // these. Rows searched at h itself need no cut: within is then the candidates.
  const std::uint64_t* offsets = nullptr;
  const std::uint32_t* candidates = nullptr;
  const std::uint32_t* within = nullptr;
  std::uint32_t* within_count = nullptr;

  // Wall particles' fluid neighbours (Adami and dynamic walls, boundary/wall_neighbors.hpp): CSR by particle
  // index, wall_nbr + wall_start[b] .. wall_nbr + wall_start[b + 1], ascending within a row.
  const std::uint32_t* wall_start = nullptr;
  const std::uint32_t* wall_nbr = nullptr;

  // Phase table.
  const PhaseParams<Real>* phases = nullptr;

  CELLSPH_HD bool is_fluid(std::size_t j) const { return kind[j] == kFluid; }
  // The gravity wall particle b's frame sees, g - a_b (a moving wall's or a floating body's acceleration; g
  // for walls at rest): what Adami's walls and DFSPH's "hydrostatic" wall pressure extrapolate with.
  // WCSPH's Akinci walls keep g (a body's noisy a_b fed back into its own pressure: docs/scenes.md).
  CELLSPH_HD V wall_gravity(const V& g, std::size_t b) const { return wall_a ? V(g - wall_a[b]) : g; }
  CELLSPH_HD const std::uint32_t* row_begin(std::size_t i) const { return within + offsets[i]; }
  CELLSPH_HD const std::uint32_t* row_end(std::size_t i) const {
    return within + offsets[i] + within_count[i];
  }
  CELLSPH_HD const std::uint32_t* candidates_begin(std::size_t i) const { return candidates + offsets[i]; }
  CELLSPH_HD const std::uint32_t* candidates_end(std::size_t i) const { return candidates + offsets[i + 1]; }
  CELLSPH_HD const PhaseParams<Real>& phase_of(std::size_t i) const {
    return phases[static_cast<std::size_t>(phase[i])];
  }
};

// Points the view's particle fields at a particle storage's arrays: Particles on the host or
// DeviceParticles in a device memory space (any BasicParticles, particles.hpp), so the field-by-field
// wiring is written once for both backends. The count and the solver's own arrays are the caller's.
template <int Dim, class Real, class Storage>
void attach_particle_fields(ParticleView<Dim, Real>& v, Storage& s) {
  v.x = s.x.data();
  v.v = s.v.data();
  v.f = s.f.data();
  v.m = s.m.data();
  v.rho = s.rho.data();
  v.p = s.p.data();
  v.h = s.h.data();
  v.color = s.color.data();
  v.mu = s.mu.data();
  v.phase = s.phase.data();
  v.level = s.level.data();
  v.tick = s.tick.data();
  v.kind = s.kind.data();
  v.id = s.id.data();
}

}  // namespace cellsph
