#pragma once
// Probes: what engineers measure in a tank, sampled from the fluid particles at fixed points.
//
//   pressure  Shepard (kernel-normalised) interpolation of the fluid pressure at `at`:
//             P(x) = sum_j p_j V_j W(x - x_j) / sum_j V_j W(x - x_j),  V_j = m_j / rho_j, fluid j only.
//             A wall sensor is a point just inside the fluid (half a spacing from the wall): the wall
//             particles do not enter the sum. No fluid within h: no value (an empty CSV field).
//   velocity  the same interpolation of each velocity component (columns NAME_x, NAME_y[, NAME_z]).
//   level     the depth of fluid above `at` on the vertical line through it (the up axis is the last
//             one): phi(y) = sum_j V_j W(x(y) - x_j) is about 1 inside the fluid and 1/2 at a free
//             surface, so the level is the highest height at which phi crosses 1/2 (linearly
//             interpolated between samples a quarter spacing apart), minus the height of `at`; 0 when
//             phi stays below 1/2 (dry, or a film thinner than about h/2).
//   layer     the depth of the water standing on `at`: going up from `at`, phi must reach 1/2 within
//             one support (else 0: dry), and the layer ends at the first height where it falls below
//             1/2 again (interpolated the same way). Water above a dry gap (a jet or spray in the air
//             over the gauge) counts for `level`, not for `layer`.
//
// The sums are brute force over the fluid particles near the probe (a column of width 2h for a level),
// so a sample costs O(n) per probe: meant for a sample every many steps, not every step.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

enum class ProbeKind { Pressure, Level, Velocity, Layer };

std::optional<ProbeKind> parse_probe_kind(std::string_view s);
std::string_view probe_kind_name(ProbeKind k);

struct Probe {
  std::string name;
  ProbeKind kind = ProbeKind::Pressure;
  std::array<double, 3> at{};  // the first Dim components are used
};

// The CSV columns of the probes after `time`, in order: NAME for a pressure or level probe,
// NAME_x, NAME_y[, NAME_z] for a velocity probe.
std::vector<std::string> probe_columns(const std::vector<Probe>& probes, int dim);

template <int Dim, class Real>
class ProbeSampler {
 public:
  // h: the kernel support; spacing: the particle spacing (sets the level's sampling step).
  ProbeSampler(std::vector<Probe> probes, KernelKind kernel, double h, double spacing);

  // One value per column of probe_columns(); NaN where no fluid particle is within h.
  [[nodiscard]] std::vector<double> sample(const Particles<Dim, Real>& p) const;

  [[nodiscard]] const std::vector<Probe>& probes() const { return probes_; }

 private:
  std::vector<Probe> probes_;
  KernelKind kernel_;
  double h_, spacing_;
};

extern template class ProbeSampler<2, float>;
extern template class ProbeSampler<2, double>;
extern template class ProbeSampler<3, float>;
extern template class ProbeSampler<3, double>;

}  // namespace cellsph
