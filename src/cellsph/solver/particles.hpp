#pragma once
// Struct-of-arrays particle storage. The one list of fields is for_each_field(): outputs,
// checkpoints, reordering and the host <-> device mirror copies (solver/device/memory_space.hpp) are
// generated from it, so a new field is added in two places only (the member and its line in the list).
// The storage is generic over its array type: Particles (std::vector, host memory) is what every
// solver, reader and writer uses; DeviceParticles<Dim, Real, Space> holds the same fields in a device
// memory space.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

// Boundary particles carry in `m` their Akinci weight psi_b = rho0 V_b (their contribution to a fluid
// density), are never integrated and only interact with fluid particles.
enum class ParticleKind : std::uint8_t { Fluid = 0, Boundary = 1 };

template <class T>
using HostArray = std::vector<T>;

template <int Dim, class Real, template <class> class Array>
struct BasicParticles {
  using V = Vec<Dim, Real>;

  Array<V> x;                 // position [m]
  Array<V> v;                 // velocity [m/s]
  Array<V> f;                 // total force of the last evaluation [N]
  Array<Real> m;              // mass [kg]
  Array<Real> rho;            // density [kg/m^3]
  Array<Real> p;              // pressure [Pa]
  Array<Real> h;              // support length [m]
  Array<Real> color;          // interface colour value c_int (paper eq. 8c)
  Array<Real> mu;             // dynamic viscosity [Pa s]
  Array<std::int32_t> phase;  // phase index into the scene's phase table
  Array<std::int32_t> level;  // per-particle time-step level n_i (dt_i = dt_max / 2^n_i)
  Array<std::int64_t> tick;   // per-particle steps: state time in units of dt_max / 2^max_level
  Array<std::uint8_t> kind;   // ParticleKind: fluid (integrated) or boundary (static, Akinci 2012)
  // Persistent identity: a permutation of 0..n-1 that travels with the particle. The Simulation
  // permutes the arrays into cell order (config reorder_every), so an index names a particle only
  // between two reorders; the id names it for the whole run (outputs are written in id order).
  Array<std::uint32_t> id;

  // The field list: fn(name, the field of s0, the field of s1, ...) for every field, in a fixed order.
  // Several storages are walked in lockstep (a host copy and its device mirror, whatever their array
  // types), so copies between them are written once over this list.
  template <class F, class... Selves>
  static void for_each_field_of(F&& fn, Selves&... s) {
    fn(std::string_view("position"), s.x...);
    fn(std::string_view("velocity"), s.v...);
    fn(std::string_view("force"), s.f...);
    fn(std::string_view("mass"), s.m...);
    fn(std::string_view("density"), s.rho...);
    fn(std::string_view("pressure"), s.p...);
    fn(std::string_view("support"), s.h...);
    fn(std::string_view("color"), s.color...);
    fn(std::string_view("viscosity"), s.mu...);
    fn(std::string_view("phase"), s.phase...);
    fn(std::string_view("level"), s.level...);
    fn(std::string_view("tick"), s.tick...);
    fn(std::string_view("kind"), s.kind...);
    fn(std::string_view("id"), s.id...);
  }
  // f(name, field) for every field of `self`, in the order above.
  template <class Self, class F>
  static void for_each_field(Self& self, F&& fn) {
    for_each_field_of(fn, self);
  }
  template <class F>
  void for_each_field(F&& fn) {
    for_each_field(*this, fn);
  }
  template <class F>
  void for_each_field(F&& fn) const {
    for_each_field(*this, fn);
  }

  [[nodiscard]] std::size_t size() const { return x.size(); }
  void resize(std::size_t n) {
    for_each_field([n](std::string_view, auto& field) { field.resize(n); });
  }
};

// The host storage every solver, reader and writer uses.
template <int Dim, class Real>
using Particles = BasicParticles<Dim, Real, HostArray>;

// Per-particle solver state that a step carries over to the next but that no output shows: a checkpoint
// holds it after the particle fields (io/checkpoint.hpp), a reorder permutes it with the particles. Like
// the particle fields, the list is for_each_field(); every field has one entry per particle (0 where the
// model keeps no such state), in the particles' order.
template <int Dim, class Real>
struct SolverState {
  // Model::Dfsph (models/dfsph.hpp): the divergence-free solve's accumulated pressure / rho^2, its next
  // warm start. (The density solve's is p / rho^2, from particle fields.)
  std::vector<Real> dfsph_kappa_v;

  template <class Self, class F>
  static void for_each_field(Self& self, F&& fn) {
    fn(std::string_view("dfsph_kappa_v"), self.dfsph_kappa_v);
  }
  template <class F>
  void for_each_field(F&& fn) {
    for_each_field(*this, fn);
  }
  template <class F>
  void for_each_field(F&& fn) const {
    for_each_field(*this, fn);
  }
  // Every field n entries of 0.
  void assign_zero(std::size_t n) {
    for_each_field([n](std::string_view, auto& field) {
      field.assign(n, typename std::remove_reference_t<decltype(field)>::value_type{});
    });
  }
};

// True when the ids ascend strictly with the index (ids 0..n-1 in order, or with the gaps that removed
// particles leave when emitters and sinks run): the order the outputs are written in.
template <int Dim, class Real>
bool in_id_order(const Particles<Dim, Real>& p) {
  for (std::size_t k = 1; k < p.id.size(); ++k)
    if (!(p.id[k - 1] < p.id[k])) return false;
  return p.id.size() == p.size();
}

// dst = src with every field gathered into ascending id order (dst particle k is the src particle with
// the k-th smallest id: the one with id k when the ids are a permutation of 0..n-1); `from` receives the
// src index of each dst particle. The ids must be unique.
template <int Dim, class Real>
void copy_in_id_order(const Particles<Dim, Real>& src, Particles<Dim, Real>& dst,
                      std::vector<std::uint32_t>& from) {
  const std::size_t n = src.size();
  CELLSPH_CHECK(src.id.size() == n, "particle ids: " << src.id.size() << " for " << n << " particles");
  constexpr std::uint32_t kNone = ~std::uint32_t{0};
  from.assign(n, kNone);
  bool permutation = true;
  for (std::size_t s = 0; s < n && permutation; ++s) {
    const std::uint32_t k = src.id[s];
    if (k >= n || from[k] != kNone) {
      permutation = false;
      break;
    }
    from[k] = static_cast<std::uint32_t>(s);
  }
  if (!permutation) {  // emitted and removed particles: sort by id
    for (std::size_t s = 0; s < n; ++s) from[s] = static_cast<std::uint32_t>(s);
    std::sort(from.begin(), from.end(),
              [&](std::uint32_t a, std::uint32_t b) { return src.id[a] < src.id[b]; });
    for (std::size_t k = 1; k < n; ++k)
      CELLSPH_CHECK(src.id[from[k - 1]] != src.id[from[k]], "particle ids are not unique: particles "
                                                                << from[k - 1] << " and " << from[k]
                                                                << " have id " << src.id[from[k]]);
  }
  dst.resize(n);
  Particles<Dim, Real>::for_each_field(src, [&](std::string_view name, const auto& field) {
    Particles<Dim, Real>::for_each_field(dst, [&](std::string_view dname, auto& out) {
      if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field)>,
                                   std::remove_cvref_t<decltype(out)>>) {
        if (dname != name) return;
        for (std::size_t k = 0; k < n; ++k) out[k] = field[from[k]];
      }
    });
  });
}

}  // namespace cellsph
