#pragma once
// Ihmsen et al.'s implicit incompressible SPH (models/iisph.hpp: iisph_step) on DFSPH's passes and arrays
// (dfsph_stepper.hpp).
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/solver/models/dfsph_stepper.hpp"
#include "cellsph/solver/models/iisph.hpp"

namespace cellsph {

template <int Dim, class Real, class Ctx>
class IisphStepper final : public ImplicitPressureStepper<Dim, Real, Ctx> {
 public:
  explicit IisphStepper(const SolverConfig<Dim, Real>& cfg) : bound_(double(cfg.dfsph.max_density_error)) {}

  // The last step's iterations, its average density error and step.
  [[nodiscard]] std::string progress(const DfsphStats& st, Real last_dt) const override {
    return "  iisph " + std::to_string(st.last_density_iterations) + " iterations, err " +
           format_number("%.3f", st.last_density_error) + "%, dt " +
           format_number("%.3g", 1e3 * double(last_dt)) + " ms" + implicit_hits_progress(st);
  }
  // Iterations a step, errors and solves stopped at max_iterations; where a step's time goes.
  [[nodiscard]] std::vector<std::string> summary(const DfsphStats& st, double search_ms) const override {
    const double n = double(std::max<std::uint64_t>(st.steps, 1));
    const double its = double(st.density_iterations);
    return {"iisph: " + format_number("%.2f", its / n) + " iterations/step, " +
                implicit_errors_summary(st, bound_),
            "iisph ms/step: search " + format_number("%.3g", search_ms / n) + wall_map_ms(st, n) +
                ", density+alpha " + format_number("%.3g", st.ms_factor / n) + ", non-pressure forces " +
                format_number("%.3g", st.ms_nonpressure / n) + ", pressure solve " +
                format_number("%.3g", st.ms_density / n) + ", drift " +
                format_number("%.3g", st.ms_drift / n) + " (" +
                format_number("%.3g", its > 0 ? st.ms_density / its : 0.0) + " ms an iteration)"};
  }

  Real advance(Ctx& c) override {
    const ParticleView<Dim, Real> pv = this->prepare(c);
    const Real dt = iisph_step(c.cfg(), pv, c.fluid_by_pairs(), c.all(), this->diameter_, this->stats_,
                               c.step_number(), c.implicit_exchange());
    c.forces_done();
    return dt;
  }

 private:
  double bound_;  // iisph.max_density_error [%]
};

}  // namespace cellsph
