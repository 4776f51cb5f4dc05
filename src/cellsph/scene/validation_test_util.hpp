#pragma once
// Helpers of the validation tests (scene/validation_test.cpp, scene/dam_break_front_test.cpp): the data
// tables of data/validation/, and a run of a scene that samples its probes as `cellsph run` does (when
// the clock passes k * probes_every, at most once per step).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/core/test_paths.hpp"
#include "cellsph/probes/probes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph::validation {

// A tab-separated table of data/validation/FILE: '#' lines are comments, the first other line is the
// header. Empty when the file is missing or malformed (the caller asserts on it).
inline std::map<std::string, std::vector<double>> read_table(const std::string& file) {
  std::ifstream in(std::string(cellsph::test::source_dir()) + "/data/validation/" + file);
  std::map<std::string, std::vector<double>> cols;
  std::vector<std::string> head;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    if (head.empty()) {
      for (std::string h; std::getline(ls, h, '\t');) head.push_back(h);
      continue;
    }
    std::size_t k = 0;
    for (std::string v; std::getline(ls, v, '\t'); ++k) {
      if (k >= head.size()) return {};
      cols[head[k]].push_back(std::stod(v));
    }
    if (k != head.size()) return {};
  }
  return cols;
}

// Linear interpolation of (t, v) at x (t ascending); the end values outside.
inline double interp(const std::vector<double>& t, const std::vector<double>& v, double x) {
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  std::size_t k = 1;
  while (t[k] < x) ++k;
  return v[k - 1] + (x - t[k - 1]) / (t[k] - t[k - 1]) * (v[k] - v[k - 1]);
}

// First time the series reaches `threshold`, linearly interpolated; NaN when it never does.
inline double arrival(const std::vector<double>& t, const std::vector<double>& v, double threshold) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (v[k] >= threshold) {
      if (k == 0) return t[0];
      return t[k - 1] + (threshold - v[k - 1]) / (v[k] - v[k - 1]) * (t[k] - t[k - 1]);
    }
  return std::numeric_limits<double>::quiet_NaN();
}

// RMS of the run's samples with t <= t_end against the reference (interpolated at the sample times).
inline double rms_error(const std::vector<double>& t, const std::vector<double>& v,
                        const std::vector<double>& ref_t, const std::vector<double>& ref_v, double t_end) {
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < t.size() && t[k] <= t_end; ++k) {
    const double d = (std::isnan(v[k]) ? 0.0 : v[k]) - interp(ref_t, ref_v, t[k]);
    sum += d * d;
    ++n;
  }
  return n ? std::sqrt(sum / n) : std::numeric_limits<double>::quiet_NaN();
}

// The probes of a run: time and one series per column of probe_columns().
struct ProbeSeries {
  std::vector<double> time;
  std::map<std::string, std::vector<double>> columns;
};

// Runs the scene until t_end on one thread, sampling its probes as `cellsph run` does (t = 0 included).
template <int Dim, class Real>
ProbeSeries run_probes(const Scene<Dim, Real>& scene, double t_end) {
  ScopedThreads one(1);
  Simulation<Dim, Real> sim(scene.solver, scene.particles);
  const ProbeSampler<Dim, Real> sampler(scene.probes, scene.solver.density_kernel,
                                        double(scene.solver.support), double(scene.spacing));
  const auto names = probe_columns(scene.probes, Dim);
  ProbeSeries out;
  std::uint64_t next = 0;
  auto due = [&] { return double(sim.time()) >= double(next) * scene.probes_every * (1 - 1e-12); };
  auto sample = [&] {
    if (!due()) return;
    const auto v = sampler.sample(sim.particles());
    out.time.push_back(double(sim.time()));
    for (std::size_t k = 0; k < names.size(); ++k) out.columns[names[k]].push_back(v[k]);
    while (due()) ++next;
  };
  sample();
  while (double(sim.time()) < t_end) {
    sim.step();
    sample();
  }
  return out;
}

}  // namespace cellsph::validation
