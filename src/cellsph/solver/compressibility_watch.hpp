#pragma once
// A weakly compressible run (the paper's model, WCSPH) stays near incompressible only while its speed of
// sound is ten times its fastest flow: then the density varies by about 1% (Monaghan 1994). The watch
// looks at the particles when a frame is written and says, once per kind, when a phase's mean
// compression passes 1% or its largest 3%, or the Mach number passes 0.1, naming the key that fixes it
// (docs/physics.md, "Speed of sound"). It reads only: the run's bits do not change.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cellsph/core/format.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

inline constexpr double kWarnMeanCompression = 0.01;
inline constexpr double kWarnMaxCompression = 0.03;
inline constexpr double kWarnMach = 0.1;

template <int Dim, class Real>
class CompressibilityWatch {
 public:
  // The warnings the particles at time t call for that were not given before (none for DFSPH and IISPH,
  // whose pressure solve bounds the density error itself).
  std::vector<std::string> check(const SolverConfig<Dim, Real>& cfg, const Particles<Dim, Real>& p,
                                 double t) {
    std::vector<std::string> out;
    if (implicit_pressure(cfg.model)) return out;
    const std::vector<PhaseState> st = phase_states(cfg, p);
    for (std::size_t k = 0; k < st.size(); ++k) {
      if (st[k].count == 0) continue;
      const double c = double(cfg.eos.sound_speed(cfg.phases[k].rest_density));
      const std::string who = "phase " + std::to_string(k) + " (" + cfg.phases[k].name + ")";
      const std::string fix = "raise /solver/eos/stiffness (now " +
                              format_number("%.4g", double(cfg.eos.stiffness)) + ", speed of sound " +
                              format_number("%.3g", c) + " m/s)";
      const double mean = st[k].compression_sum / double(st[k].count);
      if (!mean_ && mean > kWarnMeanCompression) {
        mean_ = true;
        add(out, t, who + ": mean density " + percent(mean) + " above rest (over 1%): " + fix);
      }
      if (!max_ && st[k].compression_max > kWarnMaxCompression) {
        max_ = true;
        add(out, t,
            who + ": largest density " + percent(st[k].compression_max) + " above rest (over 3%): " + fix);
      }
      const double mach = std::sqrt(st[k].speed2_max) / c;
      if (!mach_ && mach > kWarnMach) {
        mach_ = true;
        add(out, t,
            who + ": Mach number " + format_number("%.3g", mach) + " (fastest particle " +
                format_number("%.3g", std::sqrt(st[k].speed2_max)) + " m/s; over 0.1): " + fix);
      }
    }
    return out;
  }

  // Every warning given, for the run's summary.
  [[nodiscard]] const std::vector<std::string>& given() const { return given_; }

 private:
  struct PhaseState {
    std::size_t count = 0;
    double compression_sum = 0, compression_max = 0, speed2_max = 0;
  };

  static std::vector<PhaseState> phase_states(const SolverConfig<Dim, Real>& cfg,
                                              const Particles<Dim, Real>& p) {
    std::vector<PhaseState> st(cfg.phases.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != std::uint8_t(ParticleKind::Fluid)) continue;
      auto& s = st[static_cast<std::size_t>(p.phase[i])];
      const double rho0 = double(cfg.phases[static_cast<std::size_t>(p.phase[i])].rest_density);
      const double e =
          std::max(double(p.rho[i]) / rho0 - 1, 0.0);  // the deficit at a free surface is no error
      ++s.count;
      s.compression_sum += e;
      s.compression_max = std::max(s.compression_max, e);
      s.speed2_max = std::max(s.speed2_max, double(norm2(p.v[i])));
    }
    return st;
  }

  static std::string percent(double x) { return format_number("%.2g", 100 * x) + "%"; }

  void add(std::vector<std::string>& out, double t, const std::string& text) {
    const std::string line = "t = " + format_number("%.4g", t) + " s: " + text;
    out.push_back(line);
    given_.push_back(line);
  }

  bool mean_ = false, max_ = false, mach_ = false;
  std::vector<std::string> given_;
};

}  // namespace cellsph
