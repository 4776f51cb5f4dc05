// The engineering validation scenes at CI resolution, against the measured data of data/validation/
// (docs/physics.md, "Validation", has the finer runs and scripts/validate.py the comparison at any
// spacing). The bounds are the coarse run's measured errors with a margin, justified there against the
// finer runs; nothing in the scenes is fitted to the data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "cellsph/scene/scene.hpp"
#include "cellsph/scene/validation_test_util.hpp"

namespace cellsph {
namespace {

using validation::arrival;
using validation::read_table;
using validation::rms_error;

constexpr double kG = 9.81;

// Bounds. lobovsky-2014 at this 0.02 m (H / 15): level RMS error 0.8, 12.7, 17.7, 10.6% of each
// gauge's peak, arrivals -6.4, -3.9, -3.7%; at the full 0.005 m (H / 60, scripts/validate.py): 1.8, 7.7,
// 9.1, 8.4% and -8.1, -9.3, -5.1% (the instant release leads the gate's by 0.016-0.029 s, docs/physics.md).
// So 20% for the RMS (the coarse run's 2-particle-deep layers, 3-9 points above the fine run) and 10% for
// the arrivals (the fine run's lead, which the coarse run shares).
constexpr double kLobovskyRms = 0.20, kLobovskyArrival = 0.10;
// lobovsky-2014-gate (the experiment's gate, lifted at 4.5 m/s) at this 0.02 m: level RMS error 1.5, 11.1,
// 17.9, 10.3%, arrivals -2.8, -1.5, +3.1%, and 0.008, 0.007, 0.028 s after the instant release's; at 0.01 m
// -6.9, -4.8, -2.7% (0.003, 0.013, 0.020 s after), at 0.005 m -5.1, -5.1, -1.8% (0.006, 0.013, 0.013 s
// after; RMS 1.2, 5.6, 6.2, 8.5%). So the RMS bound of the instant release, and 6% for the arrivals: the
// coarse run's worst 3.1% with a margin, tighter than the instant release's -6.4% here.
constexpr double kLobovskyGateArrival = 0.06;
// spheric-test2 at 0.05 m until 1 s: level RMS 24.8% (x = 1.488 m), 6.9% (0.992 m), 3.0% (the column)
// of the peak; arrivals -0.014 and 0.000 s; P1's peak +0.011 s, 2.8 times the measured 11.2 kPa, and its
// mean over 0.45-1 s +1.2%. Finer, to 2 s: 24.5%, 15.9%, 2.5%; +0.014 and +0.003 s; P1 +0.035 s, 4.3
// times, mean +28% at 0.04 m; 17.8%, 8.6%, 0.7%; +0.013, +0.008 s; +0.010 s, 3.4 times, +27% at 0.03 m.
// Summation density's pressure is noisy (docs/physics.md): its peak is a spike of one sample, which the
// bound of 5 times only keeps from blowing up; the mean after the impact is the load.
constexpr double kSphericRms = 0.35, kSphericArrival = 0.03, kSphericP1Time = 0.04, kSphericP1Peak = 4.0,
                 kSphericP1Mean = 0.5;

// lobovsky-2014 (2D, H = 0.3 m) or its variant lobovsky-2014-gate at 0.02 m (H / 15, 450 fluid particles;
// the tank spans round(1.61 / 0.02) = 81 spacings, 1.62 m) until T = t sqrt(g / H) = 6: each gauge's level
// RMS error as a fraction of its measured peak, and the arrival times (run and experiment) at the three
// gauges outside the column, printed. The experiment is the mean of its two series (one for the gauge inside
// the column), in metres.
struct LobovskyGauge {
  std::string name;
  double rms = 0, arrival = 0, arrival_exp = 0;  // arrivals NaN for the gauge inside the column
};

std::vector<LobovskyGauge> run_lobovsky(const std::string& scene_name) {
  const double s = 0.02, H = 0.3, scale = std::sqrt(H / kG), t_end = 6 * scale;
  std::string source;
  auto j = read_scene_json(scene_name, source);
  j["spacing"] = s;
  j["solver"]["support"] = 2 * s;
  const auto scene = load_scene<2, double>(j, source);
  EXPECT_EQ(scene.probes.size(), 4u) << scene_name;

  auto data = read_table("lobovsky2014_water_levels_H300.tsv");
  EXPECT_EQ(data.size(), 8u) << "lobovsky2014_water_levels_H300.tsv not found or malformed";
  if (data.size() != 8u) return {};
  std::vector<double> t_data;
  for (double T : data["T"]) t_data.push_back(T * scale);

  const auto run = validation::run_probes(scene, t_end);
  std::vector<LobovskyGauge> out;
  for (const std::string g : {"h_x0300", "h_x0865", "h_x1114", "h_x1363"}) {
    std::vector<std::vector<double>> series;
    for (const auto& [name, v] : data)
      if (name == g || name.rfind(g + "_", 0) == 0) {
        series.emplace_back();
        for (double x : v) series.back().push_back(x * H);
      }
    EXPECT_FALSE(series.empty()) << g;
    std::vector<double> mean(t_data.size(), 0.0);
    double peak = 0;
    for (std::size_t k = 0; k < t_data.size(); ++k) {
      for (const auto& v : series) mean[k] += v[k] / double(series.size());
      if (t_data[k] <= t_end) peak = std::max(peak, mean[k]);
    }
    const auto& level = run.columns.at(g);
    LobovskyGauge r{g, rms_error(run.time, level, t_data, mean, t_end) / peak,
                    std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    std::cout << "[" << scene_name << "] " << g << ": level RMS error " << 100 * r.rms << "% of the peak "
              << peak << " m";
    if (g != "h_x0300") {
      const double threshold = 0.1 * H;
      r.arrival_exp = 0;
      for (const auto& v : series) r.arrival_exp += arrival(t_data, v, threshold) / double(series.size());
      r.arrival = arrival(run.time, level, threshold);
      std::cout << ", arrival " << r.arrival << " s against " << r.arrival_exp << " s ("
                << 100 * (r.arrival - r.arrival_exp) / r.arrival_exp << "%)";
    }
    std::cout << "\n";
    out.push_back(r);
  }
  return out;
}

TEST(Lobovsky2014, CoarseLevelsAndArrivalTimes) {
  const auto gauges = run_lobovsky("lobovsky-2014");
  ASSERT_EQ(gauges.size(), 4u);
  for (const auto& g : gauges) {
    EXPECT_LE(g.rms, kLobovskyRms) << g.name;
    if (g.name != "h_x0300") {
      EXPECT_NEAR(g.arrival, g.arrival_exp, kLobovskyArrival * g.arrival_exp) << g.name;
    }
  }
}

// The explanation of the instant release's early arrivals, tested directly: lobovsky-2014-gate releases the
// same column by the experiment's gate (lifted at 4.5 m/s from t = 0, the experiment's time origin). Its
// front must arrive later than the instant release's at every gauge, and within kLobovskyGateArrival of the
// experiment, which the instant release misses at this spacing (-6.4% at x = 0.865 m).
TEST(Lobovsky2014, GateDelaysTheArrivalsTowardsTheExperiment) {
  const auto instant = run_lobovsky("lobovsky-2014");
  const auto gate = run_lobovsky("lobovsky-2014-gate");
  ASSERT_EQ(instant.size(), 4u);
  ASSERT_EQ(gate.size(), 4u);
  for (std::size_t k = 0; k < gate.size(); ++k) {
    const auto& g = gate[k];
    EXPECT_LE(g.rms, kLobovskyRms) << g.name;
    if (g.name == "h_x0300") continue;
    EXPECT_GT(g.arrival, instant[k].arrival)
        << g.name << ": the gate's front is not later than the instant release's";
    EXPECT_NEAR(g.arrival, g.arrival_exp, kLobovskyGateArrival * g.arrival_exp) << g.name;
  }
}

// spheric-test2 (3D) at spacing kSphericSpacing until kSphericEnd: the first impact on the box. The tank,
// the column and the sensors are placed on the spacing's lattice as scripts/validate.py does: the tank ends
// at W = round(3.22 / s) s, the column is the round(1.228 / s) spacings before W, and a sensor is half a
// spacing outside the box's lattice face.
constexpr double kSphericSpacing = 0.05, kSphericEnd = 1.0;

TEST(SphericTest2, CoarseFirstImpact) {
  const double s = kSphericSpacing;
  std::string source;
  auto j = read_scene_json("spheric-test2", source);
  j["spacing"] = s;
  j["solver"]["support"] = 2 * s;
  const double w = std::round(3.22 / s) * s, x0 = w - std::round(1.228 / s) * s;
  j["fluids"][0]["min"] = {x0, 0, 0};
  j["fluids"][0]["max"] = {w, 1.0, 0.55};
  j["boundary"]["walls"]["max"] = {w, 1.0, 1.0};
  const double face = 0.6635 + std::round(0.161 / s) * s, top = std::round(0.161 / s) * s;
  auto& probes = j["probes"];  // the scene's order: 4 level gauges, P1-P4 on the face, P5-P8 on the top
  ASSERT_EQ(probes.size(), 12u);
  for (std::size_t k = 4; k < 8; ++k) probes[k]["at"][0] = face + s / 2;
  for (std::size_t k = 8; k < 12; ++k) probes[k]["at"][2] = top + s / 2;
  const auto scene = load_scene<3, float>(j, source);
  ASSERT_EQ(scene.probes.size(), 12u);

  auto data = read_table("spheric_test2_kleefsman2005.tsv");
  ASSERT_EQ(data.size(), 13u) << "spheric_test2_kleefsman2005.tsv not found or malformed";
  const auto& t_data = data["t_s"];
  const auto run = validation::run_probes(scene, kSphericEnd);

  // Levels at the two gauges the water reaches before kSphericEnd, and the gauge in the column.
  for (const std::string g : {"level_x1488", "level_x0992", "level_x2638"}) {
    double peak = 0;
    for (std::size_t k = 0; k < t_data.size() && t_data[k] <= kSphericEnd; ++k)
      peak = std::max(peak, data[g][k]);
    const auto& level = run.columns.at(g);
    const double rms = rms_error(run.time, level, t_data, data[g], kSphericEnd) / peak;
    std::cout << "[spheric] " << g << ": level RMS error " << 100 * rms << "% of the peak " << peak << " m";
    EXPECT_LE(rms, kSphericRms) << g;
    if (g != "level_x2638") {
      const double t_exp = arrival(t_data, data[g], 0.05), t_sim = arrival(run.time, level, 0.05);
      std::cout << ", arrival " << t_sim << " s against " << t_exp << " s";
      EXPECT_NEAR(t_sim, t_exp, kSphericArrival) << g;
    }
    std::cout << "\n";
  }
  // P1's first impact (t < 1 s): peak time and pressure.
  auto peak_of = [](const std::vector<double>& t, const std::vector<double>& p) {
    std::size_t best = 0;
    for (std::size_t k = 0; k < t.size() && t[k] <= kSphericEnd; ++k)
      if (!std::isnan(p[k]) && (std::isnan(p[best]) || p[k] > p[best])) best = k;
    return std::make_pair(t[best], p[best]);
  };
  const auto [te, pe] = peak_of(t_data, data["P1"]);
  const auto [ts, ps] = peak_of(run.time, run.columns.at("P1"));
  std::cout << "[spheric] P1: peak " << ps << " Pa at " << ts << " s against " << pe << " Pa at " << te
            << " s\n";
  EXPECT_NEAR(ts, te, kSphericP1Time);
  EXPECT_NEAR(ps, pe, kSphericP1Peak * pe);
  // P1's mean over the half second after the impact.
  auto mean_of = [](const std::vector<double>& t, const std::vector<double>& p) {
    double sum = 0;
    int n = 0;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (t[k] >= 0.45 && t[k] <= 1.0 && !std::isnan(p[k])) {
        sum += p[k];
        ++n;
      }
    return n ? sum / n : std::numeric_limits<double>::quiet_NaN();
  };
  const double me = mean_of(t_data, data["P1"]), ms = mean_of(run.time, run.columns.at("P1"));
  std::cout << "[spheric] P1: mean over 0.45-1 s " << ms << " Pa against " << me << " Pa\n";
  EXPECT_NEAR(ms, me, kSphericP1Mean * me);
}

}  // namespace
}  // namespace cellsph
