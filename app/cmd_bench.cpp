// `cellsph bench ...`: benchmarks printed as tables. `cellsph bench` alone lists them.
//
// `cellsph bench neighbors` follows the paper's Table 1 (build and query time per method), adding
// what a fair comparison of exact methods needs: pairs found, distance tests per neighbour found
// (the cost of a method's over-approximation), and memory: the bytes the search reports holding,
// the neighbour lists' own size, and the growth of the process's peak resident set during
// build + find_all, measured by the kernel (VmHWM after resetting it through /proc/self/clear_refs).
//
// `cellsph bench sph` times Simulation::step(): Table 1's split into neighbour search and dynamics for
// the paper's 1600-particle dam breaks with every method, and fluid particle-steps per second for the
// 3D dam break rescaled to 10^5 and 10^6 fluid particles.
#include <malloc.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/neighbors/point_sets.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"
#include "commands.hpp"

namespace cellsph::app {

namespace {

constexpr std::size_t kAllPairsLimit = 20000;  // O(n^2): ~4e8 distance tests, a few seconds

struct BenchArgs {
  std::string sizes = "10000,100000,1000000";
  std::string methods;
  std::string radii = "2,4";
  std::string sets = "lattice,uniform,uniform-cells,clustered";
  int threads = 0;
  bool threads_given = false;
  int subdivision = 1;
  int dim = 3;
  int repeat = 3;
  bool quick = false;
  bool unsorted_rows = false;
};

// ---- memory of this process, from /proc (Linux) --------------------------------------------------
std::optional<std::uint64_t> status_kb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::string k = std::string(key) + ":";
  while (std::getline(f, line)) {
    if (line.rfind(k, 0) != 0) continue;
    std::uint64_t v = 0;
    const auto b = line.find_first_of("0123456789");
    if (b == std::string::npos) return std::nullopt;
    std::from_chars(line.data() + b, line.data() + line.size(), v);
    return v;
  }
  return std::nullopt;
}

// Resets the kernel's peak-RSS mark (VmHWM) to the current RSS. False where not permitted.
bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  f.flush();
  return static_cast<bool>(f);
}

// ---- parsing of the list options ------------------------------------------------------------------
template <class T>
std::vector<T> parse_list(const std::string& option, const std::string& text, T min_value) {
  std::vector<T> out;
  std::size_t b = 0;
  while (b <= text.size()) {
    const auto c = std::min(text.find(',', b), text.size());
    const std::string item = text.substr(b, c - b);
    T v{};
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !(v >= min_value))
      throw InputError(option + ": '" + item + "' is not a number >= " + std::to_string(min_value) +
                       " (in '" + text + "')");
    out.push_back(v);
    b = c + 1;
  }
  return out;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (b <= text.size()) {
    const auto c = std::min(text.find(',', b), text.size());
    out.push_back(text.substr(b, c - b));
    b = c + 1;
  }
  return out;
}

// ---- one measured run ------------------------------------------------------------------------------
struct Row {
  SearchStats stats;  // best build and query over the repetitions
  std::uint64_t lists_bytes = 0;
  std::optional<std::uint64_t> peak_growth_bytes;
  std::uint64_t checksum = 0;
};

// FNV-1a over the CSR lists: equal checksums across methods mean equal neighbour sets (rows are
// sorted, so the lists are canonical).
std::uint64_t checksum(const NeighborList& nl) {
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&h](std::uint64_t v) {
    h ^= v;
    h *= 1099511628211ULL;
  };
  for (std::uint64_t o : nl.offsets) mix(o);
  for (std::uint32_t j : nl.indices) mix(j);
  return h;
}

template <int Dim>
Row measure(const std::vector<Vec<Dim, double>>& x, double radius, const SearchOptions& opt, int repeat) {
  Row row;
  for (int rep = 0; rep < repeat; ++rep) {
    NeighborSearch<Dim, double> ns(opt);
    NeighborList nl;
    // Give freed memory back first so the baseline is the live set, not the allocator's cache.
    ::malloc_trim(0);
    const auto rss0 = status_kb("VmRSS");
    const bool reset = rss0 && reset_peak_rss();
    ns.build(x, radius);
    ns.find_all(nl);
    const auto hwm = status_kb("VmHWM");
    const SearchStats& s = ns.stats();
    if (rep == 0) {
      row.stats = s;
      row.lists_bytes = nl.memory_bytes();
      if (reset && hwm) row.peak_growth_bytes = (*hwm > *rss0 ? *hwm - *rss0 : 0) * 1024;
      // Rows left in the search's order are sorted here, untimed, so the checksum still compares
      // neighbour sets.
      if (!opt.sorted_rows)
        parallel_for(nl.size(), [&](std::size_t i) {
          std::sort(nl.indices.begin() + static_cast<std::ptrdiff_t>(nl.offsets[i]),
                    nl.indices.begin() + static_cast<std::ptrdiff_t>(nl.offsets[i + 1]));
        });
      row.checksum = checksum(nl);
    } else {
      row.stats.build_ms = std::min(row.stats.build_ms, s.build_ms);
      row.stats.query_ms = std::min(row.stats.query_ms, s.query_ms);
    }
    // Large sets: one run is long enough to be stable.
    if (s.build_ms + s.query_ms > 2000) break;
  }
  return row;
}

double mib(std::uint64_t bytes) {
  return static_cast<double>(bytes) / (1024.0 * 1024.0);
}

void print_header() {
  std::printf("  %-13s %10s %10s %10s %12s %9s %10s %10s %10s %7s  %s\n", "method", "build ms", "query ms",
              "total ms", "pairs", "cand/nbr", "stats MiB", "lists MiB", "peak MiB", "peak/l", "check");
}

template <int Dim>
void bench_set(const std::string& title, const std::vector<Vec<Dim, double>>& x, double radius,
               const std::vector<Method>& methods, const BenchArgs& a) {
  std::printf("\n== %s ==\n", title.c_str());
  print_header();
  std::optional<std::uint64_t> reference;  // checksum of the first method that ran
  std::string reference_name;
  for (Method m : methods) {
    const std::string name(method_name(m));
    if (m == Method::AllPairs && x.size() > kAllPairsLimit) {
      std::printf("  %-13s skipped: O(n^2) is only run up to n = %zu\n", name.c_str(), kAllPairsLimit);
      continue;
    }
    Row r;
    try {
      r = measure<Dim>(
          x, radius, {.method = m, .subdivision = a.subdivision, .sorted_rows = !a.unsorted_rows}, a.repeat);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      std::printf("  %-13s not available: %s\n", name.c_str(), e.what());
      std::fflush(stdout);
      continue;
    }
    const SearchStats& s = r.stats;
    std::string check;
    if (!reference) {
      reference = r.checksum;
      reference_name = name;
      check = "reference";
    } else {
      check = r.checksum == *reference ? "same as " + reference_name : "DIFFERS from " + reference_name;
    }
    char peak[32] = "n/a", ratio[32] = "n/a";
    if (r.peak_growth_bytes) {
      std::snprintf(peak, sizeof peak, "%.1f", mib(*r.peak_growth_bytes));
      if (r.lists_bytes > 0)
        std::snprintf(ratio, sizeof ratio, "%.2f",
                      static_cast<double>(*r.peak_growth_bytes) / static_cast<double>(r.lists_bytes));
    }
    const double per_nbr =
        s.pairs > 0 ? static_cast<double>(s.candidates) / static_cast<double>(s.pairs) : 0.0;
    std::printf("  %-13s %10.2f %10.2f %10.2f %12llu %9.2f %10.1f %10.1f %10s %7s  %s\n", name.c_str(),
                s.build_ms, s.query_ms, s.build_ms + s.query_ms, static_cast<unsigned long long>(s.pairs),
                per_nbr, mib(s.memory_bytes), mib(r.lists_bytes), peak, ratio, check.c_str());
    std::fflush(stdout);
  }
}

template <int Dim>
void bench_neighbors(const BenchArgs& a, const std::vector<Method>& methods,
                     const std::vector<std::size_t>& sizes, const std::vector<double>& radii,
                     const std::vector<std::string>& sets) {
  if constexpr (Dim == 3) {
    const auto dam = point_sets::paper_dam_break<3, double>();
    bench_set<3>("dam-break (paper sec. 5): n=1600, 10x20x8 lattice, spacing 0.010627 m, h=0.05 m", dam,
                 point_sets::kPaperDamBreakH, methods, a);
  } else {
    std::printf("\n(dam-break set skipped: the paper's set is 3D)\n");
  }
  const double s = 1.0;  // lattice spacing; radii are given in units of it
  for (std::size_t n : sizes) {
    for (const std::string& set : sets) {
      std::vector<Vec<Dim, double>> x;
      std::string what;
      if (set == "lattice") {
        x = point_sets::jittered_lattice<Dim, double>(n, s, 0.01);
        what = "jittered lattice (jitter 0.01 s)";
      } else if (set == "uniform") {
        // At the lattice's density: n as requested, box side n^(1/Dim) s.
        x = point_sets::uniform_random<Dim, double>(n, s);
        what = "uniform random, lattice density";
      } else if (set == "uniform-cells") {
        x = point_sets::uniform_in_cell_order<Dim, double>(n, s);
        what = "uniform random in cell order (cells of 2 s)";
      } else {
        x = point_sets::clustered<Dim, double>(n, s);
        what = "clustered (8 Gaussian blobs)";
      }
      for (double r : radii) {
        char title[160];
        std::snprintf(title, sizeof title, "%s, %dD, n=%zu, r=%gs", what.c_str(), Dim, x.size(), r);
        bench_set<Dim>(title, x, r * s, methods, a);
      }
    }
  }
}

void run_bench_neighbors(const BenchArgs& a) {
  std::vector<Method> methods;
  if (a.methods.empty()) {
    methods.assign(std::begin(kAllMethods), std::end(kAllMethods));
  } else {
    for (const auto& name : split(a.methods)) {
      const auto m = parse_method(name);
      if (!m)
        throw InputError("--methods: unknown method '" + name + "' (expected a comma-separated list of " +
                         method_names_joined(",") + ")");
      methods.push_back(*m);
    }
  }
  auto sizes = parse_list<std::size_t>("--sizes", a.sizes, 1);
  if (a.quick) sizes = {3000};
  const auto radii = parse_list<double>("--radii", a.radii, std::numeric_limits<double>::min());
  const auto sets = split(a.sets);
  for (const auto& set : sets)
    if (set != "lattice" && set != "uniform" && set != "uniform-cells" && set != "clustered")
      throw InputError("--sets: unknown point set '" + set +
                       "' (expected a comma-separated list of lattice, uniform, uniform-cells, clustered)");
  if (a.subdivision < 1)
    throw InputError("--subdivision: must be >= 1, got " + std::to_string(a.subdivision));
  if (a.threads_given && a.threads < 1)
    throw InputError("--threads: must be >= 1, got " + std::to_string(a.threads));
  if (a.repeat < 1) throw InputError("--repeat: must be >= 1, got " + std::to_string(a.repeat));
  if (a.dim != 2 && a.dim != 3) throw InputError("--dim: must be 2 or 3, got " + std::to_string(a.dim));

  ScopedThreads threads(a.threads_given ? a.threads : max_threads());
  std::printf(
      "cellsph bench neighbors: %dD, double, %d thread(s), subdivision H=%d, best of up to %d run(s)%s\n",
      a.dim, max_threads(), a.subdivision, a.repeat, a.unsorted_rows ? ", cell-index rows unsorted" : "");
  std::printf(
      "  times: build = structure, query = all CSR lists (NeighborSearch::find_all); cand/nbr = distance\n"
      "  tests per neighbour found; stats = memory_bytes reported by the search; lists = CSR size;\n"
      "  peak = growth of peak RSS (VmHWM) during build+query; peak/l = peak / lists size.\n");
  std::fflush(stdout);
  if (a.dim == 2)
    bench_neighbors<2>(a, methods, sizes, radii, sets);
  else
    bench_neighbors<3>(a, methods, sizes, radii, sets);
}

// ---- cellsph bench sph -----------------------------------------------------------------------------
struct SphArgs {
  std::string sizes = "100000,1000000";
  std::string methods;
  std::string models = "wcsph,paper";
  std::string precisions = "float,double";
  std::string backend = "cpu";
  int steps = 20;
  int warmup = 3;
  int threads = 2;
  double skin = -1;     // < 0: the scene's Verlet skin
  std::string reorder;  // reorder_every values, comma-separated; empty: the scene's
  int subdivision = 0;  // 0: the scene's H
  bool quick = false;
};

struct StepFigures {
  std::size_t fluid = 0, total = 0;
  int steps = 0;
  double neighbors_ms = 0, dynamics_ms = 0;  // per step
  double wall_ms = 0;                        // per step, around step()
  std::uint64_t pairs = 0;                   // neighbour pairs of the last search
  std::uint64_t builds = 0;                  // neighbour searches during the timed steps
  double t_end = 0;                          // simulated time after the timed steps [s]
};

// Several variants of one case (the same scene with other settings), each warmed up on its own, then
// timed step by step in turn (A B A B ...), so that the load of a shared machine weighs on all alike
// and their ratio is meaningful even when the absolute figures drift.
template <int Dim, class Real>
std::vector<StepFigures> time_steps(const std::vector<nlohmann::json>& js, const std::string& source,
                                    int warmup, int steps) {
  std::vector<std::unique_ptr<Simulation<Dim, Real>>> sims;
  for (const auto& j : js) {
    Scene<Dim, Real> scene = load_scene<Dim, Real>(j, source);
    sims.push_back(std::make_unique<Simulation<Dim, Real>>(scene.solver, std::move(scene.particles)));
    for (int s = 0; s < warmup; ++s) sims.back()->step();
  }
  std::vector<StepTimings> t0;
  for (const auto& sim : sims) t0.push_back(sim->timings());
  std::vector<double> wall(sims.size(), 0);
  for (int s = 0; s < steps; ++s)
    for (std::size_t k = 0; k < sims.size(); ++k) {
      Stopwatch sw;
      sims[k]->step();
      wall[k] += sw.ms();
    }
  std::vector<StepFigures> out;
  for (std::size_t k = 0; k < sims.size(); ++k) {
    const auto& sim = *sims[k];
    const StepTimings& t1 = sim.timings();
    StepFigures f;
    f.fluid = sim.fluid_count();
    f.total = sim.particles().size();
    f.steps = steps;
    f.neighbors_ms = (t1.neighbors - t0[k].neighbors) / steps;
    f.dynamics_ms = (t1.forces - t0[k].forces + t1.integration - t0[k].integration) / steps;
    f.wall_ms = wall[k] / steps;
    f.pairs = sim.search_stats().pairs;
    f.builds = t1.list_builds - t0[k].list_builds;
    f.t_end = static_cast<double>(sim.time());
    out.push_back(f);
  }
  return out;
}

std::vector<StepFigures> time_scene(const std::vector<nlohmann::json>& js, const std::string& source,
                                    int warmup, int steps) {
  const SceneHeader h = read_scene_header(js.front(), source);
  if (h.dim == 2)
    return h.single_precision ? time_steps<2, float>(js, source, warmup, steps)
                              : time_steps<2, double>(js, source, warmup, steps);
  return h.single_precision ? time_steps<3, float>(js, source, warmup, steps)
                            : time_steps<3, double>(js, source, warmup, steps);
}

std::vector<Method> parse_methods(const std::string& text) {
  std::vector<Method> methods;
  if (text.empty()) return {std::begin(kAllMethods), std::end(kAllMethods)};
  for (const auto& name : split(text)) {
    const auto m = parse_method(name);
    if (!m)
      throw InputError("--methods: unknown method '" + name + "' (expected a comma-separated list of " +
                       method_names_joined(",") + ")");
    methods.push_back(*m);
  }
  return methods;
}

// Total volume of the scene's fluid blocks (they do not overlap in the built-in scenes).
double fluid_volume(const nlohmann::json& j, const std::string& source) {
  double v = 0;
  for (const auto& b : j.at("fluids")) {
    double e = 1;
    const auto& lo = b.at("min");
    const auto& hi = b.at("max");
    for (std::size_t a = 0; a < lo.size(); ++a) e *= hi.at(a).get<double>() - lo.at(a).get<double>();
    v += e;
  }
  if (!(v > 0)) throw InputError(source + ": /fluids: no fluid volume to rescale");
  return v;
}

// What `bench sph` runs, from its checked arguments.
struct SphPlan {
  std::vector<Method> methods;
  std::vector<std::size_t> sizes;
  std::vector<std::string> models, precisions;
  Backend backend = Backend::Cpu;
  std::vector<long> reorders;  // empty: the scenes' value
  int steps = 0, warmup = 0;
};

// The --reorder list of step counts.
std::vector<long> parse_reorders(const std::string& text) {
  std::vector<long> reorders;
  for (const auto& r : text.empty() ? std::vector<std::string>{} : split(text)) {
    char* end = nullptr;
    const long v = std::strtol(r.c_str(), &end, 10);
    if (r.empty() || *end != 0 || v < 0 || v > 1000000)
      throw InputError("--reorder: '" + r + "' is not a step count in [0, 1000000]");
    reorders.push_back(v);
  }
  return reorders;
}

SphPlan plan_bench_sph(const SphArgs& a) {
  SphPlan p;
  p.methods = parse_methods(a.methods);
  p.sizes = parse_list<std::size_t>("--sizes", a.sizes, 1);
  p.models = split(a.models);
  for (const auto& m : p.models)
    if (m != "wcsph" && m != "paper")
      throw InputError("--models: unknown model '" + m + "' (expected wcsph,paper)");
  p.precisions = split(a.precisions);
  for (const auto& pr : p.precisions)
    if (pr != "float" && pr != "double")
      throw InputError("--precisions: unknown precision '" + pr + "' (expected float,double)");
  const auto backend = parse_backend(a.backend);
  if (!backend) throw InputError("--backend: unknown backend '" + a.backend + "' (expected cpu or cuda)");
  require_backend(*backend, "--backend");
  p.backend = *backend;
  if (a.steps < 1) throw InputError("--steps: must be >= 1, got " + std::to_string(a.steps));
  if (a.warmup < 0) throw InputError("--warmup: must be >= 0, got " + std::to_string(a.warmup));
  if (a.threads < 1) throw InputError("--threads: must be >= 1, got " + std::to_string(a.threads));
  if (a.skin != -1 && !(a.skin >= 0 && a.skin <= 1))
    throw InputError("--skin: must be in [0, 1], got " + std::to_string(a.skin));
  p.reorders = parse_reorders(a.reorder);
  if (a.subdivision < 0 || a.subdivision > 16)
    throw InputError("--subdivision: must be in [1, 16], got " + std::to_string(a.subdivision));
  p.steps = a.steps;
  p.warmup = a.warmup;
  if (a.quick) {
    p.sizes = {2000};
    p.steps = std::min(p.steps, 3);
    p.warmup = std::min(p.warmup, 1);
  }
  return p;
}

void print_bench_sph_legend(const SphArgs& a, const SphPlan& p) {
  std::printf("cellsph bench sph: %d thread(s), %d warm-up step(s), then the mean of %d step(s)\n",
              max_threads(), p.warmup, p.steps);
  std::printf(
      "  search = NeighborSearch build + find_all (Verlet lists: only when a particle has moved\n"
      "  0.45 skin; builds = searches run in the timed steps) + the displacement check; dynamics =\n"
      "  density, forces, time step, integration, walls, stability check (Simulation::timings());\n"
      "  nbr%% = search / step; step ms of the 3D table (wall) also holds the reorders into cell order.\n");
  if (p.backend != Backend::Cpu)
    std::printf(
        "  backend %s: the step runs on the device (rows rebuilt every step by its sorted grid: builds =\n"
        "  steps); Table 1 and the paper model are CPU only (docs/gpu.md).\n",
        a.backend.c_str());
}

// Table 1: the paper's three dam breaks (paper model, double), one row per scene and method.
void bench_paper_dam_breaks(const SphArgs& a, const SphPlan& p) {
  std::printf(
      "\n== Table 1: the paper's dam breaks (3D, 1600 fluid particles, paper model, double, H = %s) ==\n",
      a.subdivision > 0 ? std::to_string(a.subdivision).c_str() : "the scene's");
  std::printf("  %-18s %-13s %11s %12s %10s %6s %7s %10s\n", "scene", "method", "search ms", "dynamics ms",
              "step ms", "nbr%", "builds", "pairs");
  for (const char* name : {"paper-dam-break-1", "paper-dam-break-2", "paper-dam-break-3"}) {
    std::string source;
    const nlohmann::json base = read_scene_json(name, source);
    for (Method m : p.methods) {
      nlohmann::json j = base;
      j["neighbors"]["method"] = std::string(method_name(m));
      if (a.skin >= 0) j["neighbors"]["skin"] = a.skin;
      if (!p.reorders.empty()) j["neighbors"]["reorder_every"] = p.reorders.front();
      if (a.subdivision > 0) j["neighbors"]["subdivision"] = a.subdivision;
      const StepFigures f = time_scene({j}, source, p.warmup, p.steps).front();
      const double step = f.neighbors_ms + f.dynamics_ms;
      std::printf("  %-18s %-13s %11.3f %12.3f %10.3f %5.1f%% %7llu %10llu\n", name,
                  std::string(method_name(m)).c_str(), f.neighbors_ms, f.dynamics_ms, step,
                  100 * f.neighbors_ms / step, static_cast<unsigned long long>(f.builds),
                  static_cast<unsigned long long>(f.pairs));
      std::fflush(stdout);
    }
  }
}

// The variants of one 3D case: dam-break-3d at `spacing` (support 2 spacing, Cell Indexing) with the
// model, precision and backend asked for, once per --reorder value (or once with the scene's).
std::vector<nlohmann::json> dam_break_variants(const nlohmann::json& base, double spacing,
                                               const std::string& model, const std::string& prec,
                                               const SphArgs& a, const SphPlan& p) {
  nlohmann::json j = base;
  j["spacing"] = spacing;
  j["solver"]["support"] = 2 * spacing;
  j["solver"]["model"] = model;
  // The paper model has no artificial viscosity (eq. 8b with the phase's mu only).
  if (model == "paper") j["solver"].erase("artificial_viscosity");
  j["precision"] = prec;
  j["neighbors"]["method"] = "cell-index";
  j["solver"]["backend"] = std::string(backend_name(p.backend));
  if (a.skin >= 0) j["neighbors"]["skin"] = a.skin;
  std::vector<nlohmann::json> variants;
  for (const long r : p.reorders) {
    variants.push_back(j);
    variants.back()["neighbors"]["reorder_every"] = r;
  }
  if (variants.empty()) variants.push_back(j);
  return variants;
}

// The 3D dam break at each fluid count, model and precision asked for.
void bench_dam_break_3d(const SphArgs& a, const SphPlan& p) {
  std::string source;
  const nlohmann::json base = read_scene_json("dam-break-3d", source);
  const double volume = fluid_volume(base, source);
  std::printf(
      "\n== 3D dam break (dam-break-3d rescaled: spacing s for the requested fluid count, "
      "support 2 s, walls kept), Cell Indexing ==\n");
  std::printf("  %-8s %-7s %8s %10s %10s %11s %12s %10s %6s %7s %14s %8s %11s\n", "model", "real", "reorder",
              "fluid", "total", "search ms", "dynamics ms", "step ms", "nbr%", "builds", "Mfluid-steps/s",
              "t end s", "pairs/fluid");
  for (std::size_t n : p.sizes) {
    const double spacing = std::cbrt(volume / static_cast<double>(n));
    for (const auto& model : p.models) {
      if (p.backend != Backend::Cpu && model != "wcsph") continue;
      for (const auto& prec : p.precisions) {
        const auto variants = dam_break_variants(base, spacing, model, prec, a, p);
        const auto figures = time_scene(variants, source, p.warmup, p.steps);
        for (std::size_t k = 0; k < figures.size(); ++k) {
          const StepFigures& f = figures[k];
          const double step = f.neighbors_ms + f.dynamics_ms;
          const std::string reorder = p.reorders.empty() ? "scene" : std::to_string(p.reorders[k]);
          std::printf("  %-8s %-7s %8s %10zu %10zu %11.2f %12.2f %10.2f %5.1f%% %7llu %14.3f %8.3f %11.1f\n",
                      model.c_str(), prec.c_str(), reorder.c_str(), f.fluid, f.total, f.neighbors_ms,
                      f.dynamics_ms, f.wall_ms, 100 * f.neighbors_ms / step,
                      static_cast<unsigned long long>(f.builds),
                      static_cast<double>(f.fluid) / (f.wall_ms * 1e3), f.t_end,
                      static_cast<double>(f.pairs) / static_cast<double>(f.fluid));
        }
        std::fflush(stdout);
        ::malloc_trim(0);
      }
    }
  }
}

void run_bench_sph(const SphArgs& a) {
  const SphPlan plan = plan_bench_sph(a);
  ScopedThreads threads(a.threads);
  print_bench_sph_legend(a, plan);
  if (plan.backend == Backend::Cpu) bench_paper_dam_breaks(a, plan);
  bench_dam_break_3d(a, plan);
}

}  // namespace

void register_bench(CLI::App& app, int& result) {
  auto* sub = app.add_subcommand("bench", "Benchmarks (run without a name to list them)");
  sub->require_subcommand(0, 1);

  auto args = std::make_shared<BenchArgs>();
  auto* nb = sub->add_subcommand("neighbors", "Neighbour search: every method on the paper's point sets");
  nb->add_option("--sizes", args->sizes, "comma-separated particle counts")->capture_default_str();
  nb->add_option("--methods", args->methods,
                 "comma-separated methods (default: all): " + method_names_joined(","));
  nb->add_option("--radii", args->radii, "comma-separated radii in lattice spacings")->capture_default_str();
  nb->add_option("--sets", args->sets, "comma-separated point sets")->capture_default_str();
  auto* threads = nb->add_option("--threads", args->threads, "threads (default: all cores)");
  nb->add_option("--subdivision", args->subdivision, "subdivision factor H (cells of size h/H)")
      ->capture_default_str();
  nb->add_option("--dim", args->dim, "dimension, 2 or 3 (the dam-break set is 3D only)")
      ->capture_default_str();
  nb->add_option("--repeat", args->repeat, "runs per measurement; the fastest is reported")
      ->capture_default_str();
  nb->add_flag("--quick", args->quick, "small sizes only (3000 points), for tests and docs");
  nb->add_flag("--unsorted-rows", args->unsorted_rows,
               "cell-index leaves rows in its own order (SearchOptions::sorted_rows = false); the other "
               "methods sort as always");
  nb->callback([args, threads, &result] {
    args->threads_given = threads->count() > 0;
    run_bench_neighbors(*args);
    result = 0;
  });

  auto sargs = std::make_shared<SphArgs>();
  auto* sph =
      sub->add_subcommand("sph", "SPH step: Table 1 split (search / dynamics) and 3D particle-steps/s");
  sph->add_option("--sizes", sargs->sizes, "comma-separated fluid particle counts of the 3D dam break")
      ->capture_default_str();
  sph->add_option("--steps", sargs->steps, "timed steps per case")->capture_default_str();
  sph->add_option("--warmup", sargs->warmup, "untimed steps first")->capture_default_str();
  sph->add_option("--threads", sargs->threads, "threads")->capture_default_str();
  sph->add_option(
      "--subdivision", sargs->subdivision,
      "H-mask subdivision H of Table 1's searches (cells of size h / H; default: the scenes', 1)");
  sph->add_option(
      "--skin", sargs->skin,
      "Verlet skin (fraction of h) of every case; 0: a search every step (default: the scenes', 0.15)");
  sph->add_option(
      "--reorder", sargs->reorder,
      "reorder the particles into cell order every N steps (neighbors.reorder_every; 0: never); a "
      "comma-separated list runs the 3D cases once per value, timed in turn step by step "
      "(default: the scenes')");
  sph->add_option("--methods", sargs->methods,
                  "comma-separated methods for Table 1 (default: all): " + method_names_joined(","));
  sph->add_option("--backend", sargs->backend, "where the steps run: cpu or cuda")->capture_default_str();
  sph->add_option("--models", sargs->models, "models of the 3D runs: wcsph,paper")->capture_default_str();
  sph->add_option("--precisions", sargs->precisions, "precisions of the 3D runs: float,double")
      ->capture_default_str();
  sph->add_flag("--quick", sargs->quick, "tiny sizes (2000 fluid particles, 3 steps), for tests and docs");
  sph->callback([sargs, &result] {
    run_bench_sph(*sargs);
    result = 0;
  });

  add_bench_steps(*sub, result);

  sub->callback([sub, &result] {
    if (!sub->get_subcommands().empty()) return;
    std::cout << "Benchmarks (cellsph bench NAME --help for options):\n";
    for (const auto* s : sub->get_subcommands([](const CLI::App*) { return true; }))
      std::cout << "  " << s->get_name() << "  " << s->get_description() << "\n";
    result = 0;
  });
}

}  // namespace cellsph::app
