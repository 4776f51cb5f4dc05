#pragma once
// Emitters and sinks as a component of the Simulation (scene keys emitters and sinks; the frames, layers
// and passes in emitters.hpp). Per step: which emitters are active at its start, their buffers' particles
// held on the emitter planes through the step, then the layers due and the particles inside a sink, which
// the Simulation turns into a count change. Its part of the integrator state: the id the next emitted
// particle gets and, per emitter, how far its newest layer has travelled (checkpointed).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/emitters.hpp"
#include "cellsph/solver/particles.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

template <int Dim, class Real>
class EmittersAndSinks {
 public:
  using V = Vec<Dim, Real>;

  // Each emitter's frame and layer lattice; the first layer is due at the start (advance = one spacing), so
  // the emitted lattice continues a fluid block that begins at the emitter plane. InputError when an
  // emitter's phase has no mass. `next_id`: the particle count (ids 0..n-1 are taken).
  void init(const SolverConfig<Dim, Real>& cfg, std::uint64_t next_id) {
    next_id_ = next_id;
    for (std::size_t k = 0; k < cfg.inflow.emitters.size(); ++k) {
      const Emitter& e = cfg.inflow.emitters[k];
      const auto& phase = cfg.phases[static_cast<std::size_t>(e.phase)];
      if (!(phase.mass > 0 && std::isfinite(phase.mass)))
        throw InputError("emitters[" + std::to_string(k) + "].phase: phase '" + phase.name + "' has mass " +
                         std::to_string(phase.mass) + " (phases[" + std::to_string(e.phase) +
                         "].mass): emitted particles need one > 0");
      frames_.push_back(emitter_frame<Dim, Real>(e, cfg.inflow.spacing, double(cfg.support)));
      planes_.push_back(frames_.back());
      advance_.push_back(cfg.inflow.spacing);
    }
  }

  // Which emitters are active at time t (active_flags()); true when one is.
  bool activity(const Inflow& inflow, double t) {
    active_.assign(frames_.size(), 0);
    bool any = false;
    for (std::size_t e = 0; e < frames_.size(); ++e) {
      active_[e] = emitter_active(inflow.emitters[e], t) ? 1 : 0;
      any = any || active_[e];
    }
    return any;
  }
  [[nodiscard]] const std::uint8_t* active_flags() const { return active_.data(); }

  // The step's start: the fluid particles in the buffer of an emitter active at time t, with their positions.
  void mark(const Inflow& inflow, double t, const IndexSet& fluid, const std::vector<V>& x) {
    holding_ = activity(inflow, t);
    if (!holding_) return;
    held_of_.resize(x.size());
    held_x_.resize(x.size());
    run_pass(fluid, InflowMarkPass<Dim, Real>{x.data(), held_of_.data(), held_x_.data(), planes_.data(),
                                              active_.data(), frames_.size()});
  }
  // After the integration: the marked particles back on their emitter's line, moving at its velocity.
  void hold(const IndexSet& fluid, V* x, V* v, Real dt) const {
    if (!holding_) return;
    run_pass(fluid, InflowHoldPass<Dim, Real>{x, v, held_of_.data(), held_x_.data(), planes_.data(), dt});
  }

  // The layers due after a step of dt from the emitters active at its start (oldest first, emitter by
  // emitter): positions in xs, each one's emitter in emitter_of. SimulationError when a buffer moves more
  // than 4 spacings in one step (a fixed step far too long for the inflow: the Courant step keeps it below
  // one, and the count would run away).
  void due_layers(const Inflow& inflow, Real dt, std::vector<V>& xs, std::vector<std::int32_t>& emitter_of) {
    for (std::size_t e = 0; e < frames_.size(); ++e) {
      if (!active_[e]) continue;
      const double travel = inflow.emitters[e].velocity * double(dt);
      if (travel > 4 * inflow.spacing)
        throw SimulationError("emitters[" + std::to_string(e) + "]: velocity * dt = " +
                              std::to_string(travel) + " m in one step, more than 4 particle spacings (" +
                              std::to_string(inflow.spacing) + " m): shorten the time step");
      emit_layers(frames_[e], inflow.emitters[e].velocity, double(dt), advance_[e], xs);
      emitter_of.resize(xs.size(), static_cast<std::int32_t>(e));
    }
  }

  // Per particle 0 where a fluid particle is inside a sink, else 1; empty when none is.
  [[nodiscard]] std::vector<std::uint8_t> sink_keep(const Inflow& inflow, const IndexSet& fluid,
                                                    const std::vector<V>& x) const {
    std::vector<std::uint8_t> keep;
    if (inflow.sinks.empty()) return keep;
    keep.assign(x.size(), 1);
    run_pass(fluid,
             InflowSinkPass<Dim, Real>{{x.data(), inflow.sinks.data(), inflow.sinks.size()}, keep.data()});
    if (std::find(keep.begin(), keep.end(), std::uint8_t{0}) == keep.end()) keep.clear();
    return keep;
  }

  // SimulationError when `count` new ids would pass 2^32.
  void check_ids(std::size_t count, Real t) const {
    if (next_id_ + count > std::uint64_t{std::numeric_limits<std::uint32_t>::max()} + 1)
      throw SimulationError("emitters: the 2^32 particle ids are used up at t = " + std::to_string(t) + " s");
  }

  // The emitted particles in slots first.. of p: fluid of the emitter's phase at rest density and zero
  // pressure, moving at U along the normal (the paper model's half-step velocity too), with new ids.
  void fill_emitted(const SolverConfig<Dim, Real>& cfg, Particles<Dim, Real>& p, std::size_t first,
                    const std::vector<V>& xs, const std::vector<std::int32_t>& emitter_of) {
    for (std::size_t k = 0; k < xs.size(); ++k) {
      const std::size_t i = first + k;
      const auto e = static_cast<std::size_t>(emitter_of[k]);
      const std::int32_t ph = cfg.inflow.emitters[e].phase;
      const auto& phase = cfg.phases[static_cast<std::size_t>(ph)];
      p.x[i] = xs[k];
      p.v[i] = frames_[e].velocity;
      p.m[i] = phase.mass;
      p.rho[i] = phase.rest_density;
      p.h[i] = cfg.support;
      p.color[i] = phase.color;
      p.mu[i] = phase.viscosity;
      p.phase[i] = ph;
      p.kind[i] = static_cast<std::uint8_t>(ParticleKind::Fluid);
      p.id[i] = static_cast<std::uint32_t>(next_id_++);
    }
  }

  [[nodiscard]] std::size_t emitters() const { return frames_.size(); }
  [[nodiscard]] std::uint64_t next_id() const { return next_id_; }
  [[nodiscard]] const std::vector<double>& advance() const { return advance_; }
  // A checkpoint's state (validated by the caller); an empty `advance` starts every emitter afresh.
  void restore(std::uint64_t next_id, const std::vector<double>& advance, double spacing) {
    next_id_ = next_id;
    if (!advance.empty())
      advance_ = advance;
    else
      advance_.assign(frames_.size(), spacing);
  }

 private:
  std::vector<EmitterFrame<Dim, Real>> frames_;
  std::vector<EmitterPlane<Dim, Real>> planes_;  // the frames' planes as the passes read them
  std::vector<double> advance_;
  std::uint64_t next_id_ = 0;
  // The step's buffer: per particle its emitter or -1 and its start position (valid for the fluid slots
  // while holding_); which emitters are active at the step's start.
  std::vector<std::int32_t> held_of_;
  std::vector<V> held_x_;
  bool holding_ = false;
  std::vector<std::uint8_t> active_;
};

}  // namespace cellsph
