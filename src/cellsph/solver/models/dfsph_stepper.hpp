#pragma once
// Bender & Koschier's divergence-free SPH (models/dfsph.hpp: dfsph_step), and the arrays and statistics
// it shares with IISPH (iisph_stepper.hpp): per particle the factor alpha, a sweep's k, the step's kernel
// gradient sums and the sweeps' gathered values; per pair slot of the rows the kernel gradient; with the
// conjugate-gradient density solve (models/dfsph_cg.hpp) its vectors.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

#include "cellsph/core/format.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/solver/boundary/bender2019.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/models/model_stepper.hpp"

namespace cellsph {

// ", N solves at max_iterations" of the progress line (nothing while there are none).
inline std::string implicit_hits_progress(const DfsphStats& st) {
  return st.max_iteration_hits > 0
             ? ", " + std::to_string(st.max_iteration_hits) + " solves at max_iterations"
             : std::string();
}

// The summary's errors: "density error last L% max M% (bound B%), N solves stopped at max_iterations[ (last:
// step S, error E%)]".
inline std::string implicit_errors_summary(const DfsphStats& st, double bound) {
  std::string s = "density error last " + format_number("%.3g", st.last_density_error) + "% max " +
                  format_number("%.3g", st.max_density_error) + "% (bound " + format_number("%.3g", bound) +
                  "%), " + std::to_string(st.max_iteration_hits) + " solves stopped at max_iterations";
  if (st.max_iteration_hits)
    s += " (last: step " + std::to_string(st.last_hit_step) + ", error " +
         format_number("%.3g", st.last_hit_error) + "%)";
  return s;
}

// ", wall map M" of the summary's split: the volume-map walls' look-up a step (nothing without them).
inline std::string wall_map_ms(const DfsphStats& st, double steps) {
  return st.ms_walls > 0 ? ", wall map " + format_number("%.3g", st.ms_walls / steps) : std::string();
}

template <int Dim, class Real, class Ctx>
class ImplicitPressureStepper : public ModelStepper<Dim, Real, Ctx> {
 public:
  DfsphStats* solver_stats() override { return &stats_; }

 protected:
  // The step's arrays sized and attached to the view; the particle diameter of the CFL step, once.
  ParticleView<Dim, Real> prepare(Ctx& c) {
    const std::size_t n = c.size();
    c.count_density(c.fluid_count());
    c.count_forces(c.fluid_count());
    for (auto* a : {&alpha_, &kappa_, &mk_}) a->resize(n);
    for (auto* a : {&gsum_, &gwall_, &mv_}) a->resize(n);
    grad_.resize(c.pair_slots());
    if (c.cfg().dfsph.density_solver == DfsphDensitySolver::ConjugateGradient) {
      for (auto* a : {&cg_s_, &cg_p_, &cg_ap_}) a->resize(n);
      cg_v0_.resize(n);
      cg_active_.resize(n);
    }
    if (diameter_ == 0) diameter_ = c.particle_diameter();
    ParticleView<Dim, Real> pv = c.view();
    pv.df_alpha = alpha_.data();
    pv.df_kappa = kappa_.data();
    pv.df_grad = grad_.data();
    pv.df_gsum = gsum_.data();
    pv.df_gwall = gwall_.data();
    pv.df_mv = mv_.data();
    pv.df_mk = mk_.data();
    pv.cg_v0 = cg_v0_.data();
    pv.cg_s = cg_s_.data();
    pv.cg_p = cg_p_.data();
    pv.cg_ap = cg_ap_.data();
    pv.cg_active = cg_active_.data();
    if (c.cfg().wall_model == WallModel::VolumeMap) look_up_walls(c, pv);
    return pv;
  }

  // Volume-map walls (boundary/bender2019.hpp): each fluid particle's wall neighbour of the step.
  void look_up_walls(Ctx& c, ParticleView<Dim, Real>& pv) {
    const Stopwatch sw;
    const std::size_t n = c.size();
    for (auto* a : {&vm_rho_, &vm_w_, &vm_count_}) a->resize(n);
    for (auto* a : {&vm_g_, &vm_x_, &vm_h_}) a->resize(n);
    pv.vm_rho = vm_rho_.data();
    pv.vm_g = vm_g_.data();
    pv.vm_w = vm_w_.data();
    pv.vm_x = vm_x_.data();
    pv.vm_count = vm_count_.data();
    pv.vm_h = vm_h_.data();
    const auto& cfg = c.cfg();
    const double ratio = double(cfg.support) / double(diameter_);
    const auto full = static_cast<Real>(Dim == 3 ? 4.18879 * ratio * ratio * ratio : 3.14159 * ratio * ratio);
    with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
      run_pass(c.fluid(), VolumeMapLookupPass<Dim, Real, std::remove_cvref_t<decltype(w)>>{
                              pv, volume_map_view(cfg.volume_map), w, full, cfg.gravity});
    });
    stats_.ms_walls += sw.ms();
  }

  template <class T>
  using Array = typename Ctx::template Array<T>;
  Array<Real> alpha_, kappa_, mk_;
  Array<Vec<Dim, Real>> grad_, gsum_, gwall_, mv_;
  Array<Real> cg_s_, cg_p_, cg_ap_;
  Array<Real> vm_rho_, vm_w_, vm_count_;
  Array<Vec<Dim, Real>> vm_g_, vm_x_, vm_h_;
  Array<Vec<Dim, Real>> cg_v0_;
  Array<std::uint8_t> cg_active_;
  Real diameter_ = 0;
  DfsphStats stats_;
};

template <int Dim, class Real, class Ctx>
class DfsphStepper final : public ImplicitPressureStepper<Dim, Real, Ctx> {
 public:
  explicit DfsphStepper(const SolverConfig<Dim, Real>& cfg) : bound_(double(cfg.dfsph.max_density_error)) {}

  // The last step's sweeps (density + divergence), its average density error and step.
  [[nodiscard]] std::string progress(const DfsphStats& st, Real last_dt) const override {
    return "  dfsph " + std::to_string(st.last_density_iterations) + "+" +
           std::to_string(st.last_divergence_iterations) + " sweeps, err " +
           format_number("%.3f", st.last_density_error) + "%, dt " +
           format_number("%.3g", 1e3 * double(last_dt)) + " ms" + implicit_hits_progress(st);
  }
  // Sweeps a step, errors and solves stopped at max_iterations; where a step's time goes (the non-pressure
  // forces are summed in the divergence solve's last pass: their time is the solve's).
  [[nodiscard]] std::vector<std::string> summary(const DfsphStats& st, double search_ms) const override {
    const double n = double(std::max<std::uint64_t>(st.steps, 1));
    const double sweeps = double(st.density_iterations);
    return {"dfsph: " + format_number("%.2f", sweeps / n) + " density + " +
                format_number("%.2f", double(st.divergence_iterations) / n) + " divergence sweeps/step, " +
                implicit_errors_summary(st, bound_),
            "dfsph ms/step: search " + format_number("%.3g", search_ms / n) + wall_map_ms(st, n) +
                ", density+alpha " + format_number("%.3g", st.ms_factor / n) +
                ", divergence solve + non-pressure forces " + format_number("%.3g", st.ms_divergence / n) +
                ", kick " + format_number("%.3g", st.ms_nonpressure / n) + ", density solve " +
                format_number("%.3g", st.ms_density / n) + ", drift " +
                format_number("%.3g", st.ms_drift / n) + " (" +
                format_number("%.3g", sweeps > 0 ? st.ms_density / sweeps : 0.0) + " ms a density sweep)"};
  }

  Real advance(Ctx& c) override {
    const ParticleView<Dim, Real> pv = this->prepare(c);
    const Real dt = dfsph_step(c.cfg(), pv, c.fluid_by_pairs(), c.all(), this->diameter_, this->stats_,
                               c.step_number(), c.implicit_exchange());
    c.forces_done();
    return dt;
  }

 private:
  double bound_;  // dfsph.max_density_error [%]
};

}  // namespace cellsph
