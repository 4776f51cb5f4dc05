#pragma once
// Inflow and outflow: emitters that inject fluid on a lattice and sinks that remove it (scene keys
// `emitters` and `sinks`, docs/scenes.md "Inflow and outflow"). Everything about them is here:
//  * Emitter, Sink, Inflow: plain data (SolverConfig::inflow), checked by inflow_config_error();
//  * EmitterFrame: an emitter's unit normal, tangents and the lattice of one layer (emitter_frame());
//  * the buffer: fluid particles within [-spacing, depth) of an active emitter's plane (along its normal,
//    inside its cross-section) are held: each step they move exactly velocity * dt along the normal at
//    velocity U (InflowHoldPass), whatever the forces, so the fluid beyond the buffer always sees a full
//    kernel of fluid upstream and the inflow rate is exact;
//  * emission: an emitter keeps `advance`, the distance its newest layer has travelled since it was
//    inserted; each step of an active emitter adds U dt, and every time it reaches one spacing a new
//    layer is inserted half a spacing upstream of the plane, shifted by the excess (emit_layers()). The
//    mass crossing the plane is therefore rho0 U A per unit time exactly (A: the layer's lattice cells);
//  * sinks: fluid particles inside a sink box at the end of a step are removed (in_sink()).
// The Simulation appends new particles after the existing ones and removes particles by stable
// compaction, both in index order, so the result is the same bits for any thread count; `advance` and
// the next free id are part of the integrator state (checkpoints), so a resume is bit for bit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

enum class EmitterShape : std::uint8_t { Box, Disc };

// One emitter, as the scene gives it (lengths in m, times in s, velocity in m/s).
struct Emitter {
  EmitterShape shape = EmitterShape::Box;
  double center[3] = {0, 0, 0};  // a point of the emitter plane, the middle of the cross-section
  double normal[3] = {1, 0, 0};  // the direction of the inflow (any length > 0; normalised)
  // Box: the cross-section's side lengths along the tangents (2D: size[0], the width); disc: size[0] is
  // the diameter (2D: a segment of that width, as a box).
  double size[2] = {0, 0};
  double velocity = 0;     // U [m/s] along the normal, >= 0
  double start = 0;        // active from this time [s] ...
  double end = HUGE_VAL;   // ... until this time [s] (HUGE_VAL: forever)
  double depth = 0;        // buffer depth along the normal [m]; 0: the kernel support
  std::int32_t phase = 0;  // the phase of the emitted fluid
};

// A box [lo, hi] where fluid particles are removed.
struct Sink {
  double lo[3] = {0, 0, 0};
  double hi[3] = {0, 0, 0};
};

struct Inflow {
  std::vector<Emitter> emitters;
  std::vector<Sink> sinks;
  double spacing = 0;  // the lattice spacing of emitted layers [m] (the scene's spacing)
  [[nodiscard]] bool any() const { return !emitters.empty() || !sinks.empty(); }
};

// An emitter's plane and buffer, as the passes read them (plain data: a device holds a copy): unit normal
// n, tangents, the buffer depth.
template <int Dim, class Real>
struct EmitterPlane {
  using V = Vec<Dim, Real>;
  V center{}, normal{}, velocity{};  // velocity = U n
  V tangent[Dim - 1]{};
  Real half[2] = {0, 0};  // half the cross-section along each tangent (disc: radius in half[0])
  bool disc = false;
  Real depth = 0, spacing = 0;
};

// An emitter ready for the step: its plane and the layer's lattice offsets (relative to the centre, in
// the plane).
template <int Dim, class Real>
struct EmitterFrame : EmitterPlane<Dim, Real> {
  std::vector<Vec<Dim, Real>> layer;  // offsets of one layer's particles from the centre
};

// True when emitter e is active at time t (its buffer is held and it emits): start <= t < end.
inline bool emitter_active(const Emitter& e, double t) {
  return t >= e.start && t < e.end;
}

// Empty when `in` is valid for a `dim`-D scene with `phases` phases; otherwise "KEY: VALUE: why".
std::string inflow_config_error(const Inflow& in, int dim, std::size_t phases);

// The frame and layer lattice of `e` (valid input): the layer holds floor(size / spacing) particles
// along each tangent (at least 1), centred on the centre, at the lattice spacing; a disc keeps those of
// its square lattice within the radius.
template <int Dim, class Real>
EmitterFrame<Dim, Real> emitter_frame(const Emitter& e, double spacing, double support);

// True when x is in the buffer of emitter f: -spacing <= (x - c).n < depth, inside the cross-section.
template <int Dim, class Real>
CELLSPH_HD inline bool in_emitter_buffer(const EmitterPlane<Dim, Real>& f, const Vec<Dim, Real>& x) {
  const Vec<Dim, Real> r = x - f.center;
  const Real d = dot(r, f.normal);
  if (!(d >= -f.spacing && d < f.depth)) return false;
  if (f.disc && Dim == 3) return norm2(r - f.normal * d) <= f.half[0] * f.half[0];
  for (int a = 0; a < Dim - 1; ++a)
    if (!(std::abs(dot(r, f.tangent[a])) <= f.half[a])) return false;
  return true;
}

template <int Dim, class Real>
CELLSPH_HD inline bool in_sink(const Sink& s, const Vec<Dim, Real>& x) {
  for (int a = 0; a < Dim; ++a)
    if (!(double(x[a]) >= s.lo[a] && double(x[a]) <= s.hi[a])) return false;
  return true;
}

// Marks the fluid particles in the buffer of an active emitter: held[i] = emitter index or -1, and a held
// particle's position at the step's start in x_start[i]. Runs over the fluid set at the start of a step
// (frames: every emitter's plane; those with active[e] == 0 are skipped).
template <int Dim, class Real>
struct InflowMarkPass {
  const Vec<Dim, Real>* x;
  std::int32_t* held;
  Vec<Dim, Real>* x_start;
  const EmitterPlane<Dim, Real>* frames;
  const std::uint8_t* active;
  std::size_t count;
  CELLSPH_HD void operator()(std::size_t i) const {
    held[i] = -1;
    for (std::size_t e = 0; e < count; ++e)
      if (active[e] && in_emitter_buffer(frames[e], x[i])) {
        held[i] = static_cast<std::int32_t>(e);
        x_start[i] = x[i];
        return;
      }
  }
};

// After the integration, over the same fluid set: a held particle is put at x_start + U n dt with
// velocity U n.
template <int Dim, class Real>
struct InflowHoldPass {
  Vec<Dim, Real>* x;
  Vec<Dim, Real>* v;
  const std::int32_t* held;
  const Vec<Dim, Real>* x_start;
  const EmitterPlane<Dim, Real>* frames;
  Real dt;
  CELLSPH_HD void operator()(std::size_t i) const {
    if (held[i] < 0) return;
    const auto& f = frames[held[i]];
    x[i] = x_start[i] + f.velocity * dt;
    v[i] = f.velocity;
  }
};

// True for a particle inside one of the sinks (run over the fluid set at the end of a step).
template <int Dim, class Real>
struct InflowSinkTest {
  const Vec<Dim, Real>* x;
  const Sink* sinks;
  std::size_t count;
  CELLSPH_HD bool operator()(std::size_t i) const {
    for (std::size_t k = 0; k < count; ++k)
      if (in_sink<Dim, Real>(sinks[k], x[i])) return true;
    return false;
  }
};

// keep[i] = 0 for a fluid particle inside a sink, 1 otherwise (the end of a step).
template <int Dim, class Real>
struct InflowSinkPass {
  InflowSinkTest<Dim, Real> test;
  std::uint8_t* keep;
  CELLSPH_HD void operator()(std::size_t i) const { keep[i] = test(i) ? 0 : 1; }
};

// Advances the emitter's `advance` by U dt and appends to `out` the positions of the layers due
// (oldest first): each at the centre + the layer offsets + (advance - spacing / 2) n after the
// subtraction. Returns the number of layers.
template <int Dim, class Real>
std::size_t emit_layers(const EmitterFrame<Dim, Real>& f, double velocity, double dt, double& advance,
                        std::vector<Vec<Dim, Real>>& out) {
  advance += velocity * dt;
  std::size_t layers = 0;
  while (advance >= double(f.spacing)) {
    advance -= double(f.spacing);
    const Real d = static_cast<Real>(advance - double(f.spacing) / 2);
    for (const auto& q : f.layer) out.push_back(f.center + q + f.normal * d);
    ++layers;
  }
  return layers;
}

}  // namespace cellsph
