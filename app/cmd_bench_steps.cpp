// `cellsph bench steps`: per-particle power-of-two steps (Desbrun; paper eq. 12-13) against the global
// step dt = min_i dt_i (`courant`, the same limits), on one scene for the same simulated time.
//
// Reports the work (force and density evaluations, in particles), the sub-steps and the wall time of
//  * courant:          global steps, every particle evaluated every step;
//  * per-particle:     each particle on its own level, densities only where the due forces read them;
//  * per-particle/all: the same steps with every density computed in every sub-step (the cost before the
//                      work sets; results are bit-identical to per-particle);
// and how close the two integrations stay: the surge front (largest x of the fluid), the kinetic energy
// and the mean distance between the same particle in both runs, at synchronised times (multiples of
// dt_max, where every particle of the per-particle run is at the clock time).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"
#include "commands.hpp"

namespace cellsph::app {

namespace {

struct StepsArgs {
  std::string scene = "paper-dam-break-1";
  double end = 0.5;
  double sample = 0.05;
  double dt_max = 0.01;
  int max_level = 10;
  double stiffness = 0;  // 0: the scene's
  int threads = 2;
  std::vector<std::string> sets;  // scene edits "/json/pointer=json value"
};

struct Sample {
  double t = 0, front = 0, ke = 0;
};

struct RunFigures {
  std::string name;
  std::uint64_t steps = 0;
  StepTimings timings;
  double wall_ms = 0;
  std::vector<Sample> samples;
  std::vector<std::vector<double>> x;  // fluid positions at every sample (flattened per sample)
  std::vector<int> level_hist;         // per-particle: fluid particles per level at the end
};

template <int Dim, class Real>
RunFigures run_one(const nlohmann::json& j, const std::string& source, const StepsArgs& a, bool per_particle,
                   bool full) {
  Scene<Dim, Real> scene = load_scene<Dim, Real>(j, source);
  auto cfg = scene.solver;
  cfg.time.mode = per_particle ? TimeStepping::PerParticle : TimeStepping::Courant;
  cfg.time.dt_max = static_cast<Real>(a.dt_max);
  cfg.time.max_level = a.max_level;
  if (a.stiffness > 0) cfg.eos.stiffness = static_cast<Real>(a.stiffness);
  Simulation<Dim, Real> sim(cfg, std::move(scene.particles));
  RunFigures r;
  r.name = !per_particle ? "courant" : full ? "per-particle/all" : "per-particle";
  sim.set_full_passes(full);
  const auto& p = sim.particles();
  auto take_sample = [&] {
    Sample s;
    s.t = static_cast<double>(sim.time());
    s.front = -1e300;
    std::vector<double> xs;
    // In id order: the runs reorder their arrays on different schedules (steps vs the clock).
    std::vector<std::size_t> by_id(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) by_id[p.id[i]] = i;
    for (const std::size_t i : by_id) {
      if (p.kind[i] != static_cast<std::uint8_t>(ParticleKind::Fluid)) continue;
      s.front = std::max(s.front, static_cast<double>(p.x[i][0]));
      for (int d = 0; d < Dim; ++d) xs.push_back(static_cast<double>(p.x[i][d]));
    }
    s.ke = static_cast<double>(sim.kinetic_energy());
    r.samples.push_back(s);
    r.x.push_back(std::move(xs));
  };
  Stopwatch sw;
  double wall = 0;
  int k = 0;
  const double eps = 1e-9 * a.sample;
  while (true) {
    const double due = k * a.sample;
    if (static_cast<double>(sim.time()) >= due - eps) {
      wall += sw.ms();
      take_sample();
      ++k;
      sw.reset();
      continue;
    }
    if (static_cast<double>(sim.time()) >= a.end - eps) break;
    sim.step();
  }
  wall += sw.ms();
  r.wall_ms = wall;
  r.steps = sim.steps();
  r.timings = sim.timings();
  if (per_particle) {
    r.level_hist.assign(static_cast<std::size_t>(a.max_level) + 1, 0);
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid))
        ++r.level_hist[static_cast<std::size_t>(p.level[i])];
  }
  return r;
}

template <int Dim, class Real>
void run_steps(const nlohmann::json& j, const std::string& source, StepsArgs a) {
  if (!(a.end > 0) || !(a.sample > 0) || !(a.dt_max > 0))
    throw InputError("--end, --sample and --dt-max must be positive");
  // Samples at multiples of dt_max, where every particle of the per-particle run is at the clock time.
  a.sample = std::max(1.0, std::round(a.sample / a.dt_max)) * a.dt_max;
  if (a.max_level < 0 || a.max_level > 30) throw InputError("--max-level must be in 0..30");
  ScopedThreads threads(a.threads);
  double sound_speed = 0;
  {
    const Scene<Dim, Real> scene = load_scene<Dim, Real>(j, source);
    auto eos = scene.solver.eos;
    if (a.stiffness > 0) eos.stiffness = static_cast<Real>(a.stiffness);
    sound_speed = static_cast<double>(eos.sound_speed(scene.solver.phases.front().rest_density));
  }
  std::vector<RunFigures> runs;
  runs.push_back(run_one<Dim, Real>(j, source, a, false, false));
  runs.push_back(run_one<Dim, Real>(j, source, a, true, false));
  runs.push_back(run_one<Dim, Real>(j, source, a, true, true));
  const auto& g = runs[0];
  const auto& pp = runs[1];
  std::printf(
      "cellsph bench steps: %s, %dD, %d thread(s), to t = %g s, dt_max = %g s, max_level = %d, c = %g "
      "m/s%s\n",
      source.c_str(), Dim, a.threads, a.end, a.dt_max, a.max_level, sound_speed,
      a.stiffness > 0 ? (", stiffness " + std::to_string(a.stiffness)).c_str() : "");
  std::printf("%-17s %9s %13s %13s %13s %10s\n", "run", "steps", "force evals", "density evals",
              "normal evals", "wall ms");
  for (const auto& r : runs)
    std::printf("%-17s %9llu %13llu %13llu %13llu %10.0f\n", r.name.c_str(),
                static_cast<unsigned long long>(r.steps),
                static_cast<unsigned long long>(r.timings.force_evals),
                static_cast<unsigned long long>(r.timings.density_evals),
                static_cast<unsigned long long>(r.timings.normal_evals), r.wall_ms);
  auto ratio = [](double num, double den) { return den > 0 ? num / den : 0.0; };
  const auto work = [](const RunFigures& r) {
    return static_cast<double>(r.timings.force_evals + r.timings.density_evals + r.timings.normal_evals);
  };
  std::printf("courant / per-particle: force evals %.2fx, all evals %.2fx, wall %.2fx\n",
              ratio(static_cast<double>(g.timings.force_evals), static_cast<double>(pp.timings.force_evals)),
              ratio(work(g), work(pp)), ratio(g.wall_ms, pp.wall_ms));
  std::printf("fluid particles per level at the end (dt_max / 2^n):");
  for (std::size_t n = 0; n < pp.level_hist.size(); ++n)
    if (pp.level_hist[n]) std::printf("  n=%zu: %d", n, pp.level_hist[n]);
  std::printf("\n%8s %12s %12s %12s %12s %14s\n", "t [s]", "front glob", "front pp", "KE glob [J]",
              "KE pp [J]", "mean |dx| [m]");
  const std::size_t ns = std::min(g.samples.size(), pp.samples.size());
  for (std::size_t s = 0; s < ns; ++s) {
    double dx = 0;
    const auto& xa = g.x[s];
    const auto& xb = pp.x[s];
    const std::size_t np = xa.size() / Dim;
    for (std::size_t i = 0; i < np; ++i) {
      double d2 = 0;
      for (int d = 0; d < Dim; ++d) {
        const double e =
            xa[i * Dim + static_cast<std::size_t>(d)] - xb[i * Dim + static_cast<std::size_t>(d)];
        d2 += e * e;
      }
      dx += std::sqrt(d2);
    }
    std::printf("%8.3f %12.4f %12.4f %12.5f %12.5f %14.5f\n", pp.samples[s].t, g.samples[s].front,
                pp.samples[s].front, g.samples[s].ke, pp.samples[s].ke,
                np ? dx / static_cast<double>(np) : 0.0);
  }
}

}  // namespace

void add_bench_steps(CLI::App& bench, int& result) {
  auto a = std::make_shared<StepsArgs>();
  auto* c = bench.add_subcommand("steps", "Per-particle power-of-two steps against the global minimum step");
  c->add_option("--scene", a->scene, "built-in scene name or .json path")->capture_default_str();
  c->add_option("--end", a->end, "simulated time [s]")->capture_default_str();
  c->add_option("--sample", a->sample, "time between samples [s], rounded to a multiple of --dt-max")
      ->capture_default_str();
  c->add_option("--dt-max", a->dt_max, "largest step (both runs) [s]")->capture_default_str();
  c->add_option("--max-level", a->max_level, "finest per-particle step dt_max / 2^max_level")
      ->capture_default_str();
  c->add_option("--stiffness", a->stiffness, "equation-of-state stiffness (0: the scene's), sets c")
      ->capture_default_str();
  c->add_option("--threads", a->threads, "threads")->capture_default_str();
  c->add_option("--set", a->sets,
                "edit the scene: /json/pointer=value (a JSON value, else a string), e.g. "
                "/phases/0/viscosity=1; repeatable");
  c->callback([a, &result] {
    std::string source;
    auto j = read_scene_json(a->scene, source);
    apply_scene_edits(j, a->sets, source);
    const SceneHeader h = read_scene_header(j, source);
    if (h.dim == 2) {
      if (h.single_precision)
        run_steps<2, float>(j, source, *a);
      else
        run_steps<2, double>(j, source, *a);
    } else {
      if (h.single_precision)
        run_steps<3, float>(j, source, *a);
      else
        run_steps<3, double>(j, source, *a);
    }
    result = 0;
  });
}

}  // namespace cellsph::app
