// Diagnostic (target cellsph_dfsph_column, built with the tests): the resting column of the DFSPH
// step-limit tests (test::DfsphColumn, solver/dfsph_test.cpp) at any depth, step, support, spacing and wall
// pressure, to find the longest step at which it settles (docs/physics.md, "Model 3", "The step limit of a
// resting column"):
//   build/release/cellsph_dfsph_column DEPTH DT_MAX [--dim 2|3] [--support 2] [--mu 5] [--spacing 0.02]
//       [--width 0.4] [--walls hydrostatic|mirrored|zero] [--solver jacobi|cg] [--max-iterations 100]
//       [--until 3]
// Every half second: kinetic energy (against the tests' bound, 1e-3 M g H), the step, density and divergence
// sweeps a step, solves stopped at max_iterations, the last density error. Last line, over the final second
// (t > until - 1, as the tests sample): the pressure against rho0 g d over the lower half above the bottom
// row and over the bottom row; after the first second (all of a run shorter than 2 s): solves at
// max_iterations and the largest density error. A run that leaves its domain prints the simulation's
// diagnosis. One thread.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

using namespace cellsph;

namespace {

int usage() {
  std::fprintf(
      stderr,
      "usage: cellsph_dfsph_column DEPTH DT_MAX [--dim 2|3] [--support S] [--mu PA_S] [--spacing M]\n"
      "       [--width M] [--walls hydrostatic|mirrored|zero] [--solver jacobi|cg] [--max-iterations N]\n"
      "       [--until T]\n");
  return 2;
}

// A positive finite number, or -1.
double number(const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  return end != text && *end == '\0' && v > 0 && v < 1e30 ? v : -1;
}

template <int Dim>
void report(const Simulation<Dim, double>& sim, const DfsphStats& prev, double bound) {
  const auto& st = sim.dfsph_stats();
  const double steps = double(std::max<std::uint64_t>(st.steps - prev.steps, 1));
  std::printf(
      "t %.2f s  kinetic %.3e J (bound %.3e)  dt %.2f ms  sweeps/step %.1f + %.1f  "
      "max_iterations stops %llu  density error %.4f%%\n",
      sim.time(), sim.kinetic_energy(), bound, sim.last_dt() * 1e3,
      double(st.density_iterations - prev.density_iterations) / steps,
      double(st.divergence_iterations - prev.divergence_iterations) / steps,
      static_cast<unsigned long long>(st.max_iteration_hits - prev.max_iteration_hits),
      st.last_density_error);
}

// What the command line chose beyond the column itself.
struct Options {
  bool cg = false;
  int max_iterations = 100;
  double until = 3;
};

template <int Dim>
int run(const test::DfsphColumn<Dim>& c, const Options& o) {
  auto cfg = c.config();
  cfg.dfsph.max_iterations = o.max_iterations;
  if (o.cg) {
    cfg.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
    cfg.dfsph.warm_start_scale = 0.85;
  }
  ScopedThreads one(1);
  std::printf(
      "%dD column %g wide, %g m deep, spacing %g m, support %g s, mu %g Pa s, %s walls, %s; dt_max %g ms = "
      "%.2fx the WCSPH step of this resolution and support (%.4f ms)\n",
      Dim, c.width, c.depth, c.s, c.support, c.mu, test::dfsph_wall_pressure_name(c.walls),
      o.cg ? "CG" : "Jacobi", c.dt_max * 1e3, c.dt_max / c.wcsph_step(), c.wcsph_step() * 1e3);
  try {
    Simulation<Dim, double> sim(cfg, c.particles());
    const double bound = 1e-3 * sim.total_mass() * c.g * c.depth;
    DfsphStats prev = sim.dfsph_stats(), settled{};
    const double settle = o.until >= 2 ? 1.0 : 0.0;  // the tests settle for 1 s
    bool past_one = settle == 0;
    double max_error = 0, next = 0.5;
    typename test::DfsphColumn<Dim>::PressureSums sums;
    while (sim.time() < o.until - 1e-12) {
      sim.step();
      if (!past_one && sim.time() > settle) {
        past_one = true;
        settled = sim.dfsph_stats();
      }
      if (past_one) max_error = std::max(max_error, sim.dfsph_stats().last_density_error);
      if (sim.time() > o.until - 1) c.add_pressures(sim.particles(), sums);
      if (sim.time() >= next - 1e-12) {
        report(sim, prev, bound);
        prev = sim.dfsph_stats();
        next += 0.5;
      }
    }
    std::printf(
        "result: ratio %.2f  kinetic %.3e J (%s)  p / rho0 g d: lower half %.4f, bottom row %.4f  "
        "after %g s: max_iterations stops %llu, largest density error %.4f%%\n",
        c.dt_max / c.wcsph_step(), sim.kinetic_energy(), sim.kinetic_energy() < bound ? "settled" : "moving",
        sums.mid(), sums.bottom(), settle,
        static_cast<unsigned long long>(sim.dfsph_stats().max_iteration_hits - settled.max_iteration_hits),
        max_error);
  } catch (const std::exception& e) {
    std::printf("result: ratio %.2f  unstable: %s\n", c.dt_max / c.wcsph_step(), e.what());
    return 1;
  }
  return 0;
}

// Reads the options after DEPTH and DT_MAX into a column of dimension Dim (--dim chose it) and runs it.
template <int Dim>
int parse_and_run(int argc, char** argv) {
  test::DfsphColumn<Dim> c;
  c.depth = number(argv[1]);
  c.dt_max = number(argv[2]);
  Options o;
  for (int k = 3; k < argc; k += 2) {
    if (k + 1 >= argc) return usage();
    const std::string key = argv[k], value = argv[k + 1];
    if (key == "--dim" && (value == "2" || value == "3"))
      continue;  // main read it
    else if (key == "--support")
      c.support = number(value.c_str());
    else if (key == "--mu")
      c.mu = number(value.c_str());
    else if (key == "--spacing")
      c.s = number(value.c_str());
    else if (key == "--width")
      c.width = number(value.c_str());
    else if (key == "--until")
      o.until = number(value.c_str());
    else if (key == "--max-iterations")
      o.max_iterations = std::atoi(value.c_str());
    else if (key == "--solver" && (value == "jacobi" || value == "cg"))
      o.cg = value == "cg";
    else if (key == "--walls" && value == "hydrostatic")
      c.walls = DfsphWallPressure::Hydrostatic;
    else if (key == "--walls" && value == "mirrored")
      c.walls = DfsphWallPressure::Mirrored;
    else if (key == "--walls" && value == "zero")
      c.walls = DfsphWallPressure::Zero;
    else
      return usage();
  }
  if (c.depth <= 0 || c.dt_max <= 0 || c.support <= 0 || c.mu <= 0 || c.s <= 0 || c.width <= 0 ||
      o.until <= 0 || o.max_iterations < 1)
    return usage();
  return run(c, o);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  for (int k = 3; k + 1 < argc; k += 2)
    if (std::string(argv[k]) == "--dim" && std::string(argv[k + 1]) == "3")
      return parse_and_run<3>(argc, argv);
  return parse_and_run<2>(argc, argv);
}
