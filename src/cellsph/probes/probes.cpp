#include "cellsph/probes/probes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace cellsph {

std::optional<ProbeKind> parse_probe_kind(std::string_view s) {
  if (s == "pressure") return ProbeKind::Pressure;
  if (s == "level") return ProbeKind::Level;
  if (s == "layer") return ProbeKind::Layer;
  if (s == "velocity") return ProbeKind::Velocity;
  return std::nullopt;
}

std::string_view probe_kind_name(ProbeKind k) {
  switch (k) {
    case ProbeKind::Pressure:
      return "pressure";
    case ProbeKind::Level:
      return "level";
    case ProbeKind::Layer:
      return "layer";
    case ProbeKind::Velocity:
      break;
  }
  return "velocity";
}

std::vector<std::string> probe_columns(const std::vector<Probe>& probes, int dim) {
  static constexpr const char* kAxis[] = {"_x", "_y", "_z"};
  std::vector<std::string> out;
  for (const Probe& pr : probes) {
    if (pr.kind != ProbeKind::Velocity) {
      out.push_back(pr.name);
      continue;
    }
    for (int k = 0; k < dim; ++k) out.push_back(pr.name + kAxis[k]);
  }
  return out;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <int Dim, class Real>
bool is_fluid(const Particles<Dim, Real>& p, std::size_t j) {
  return p.kind[j] == static_cast<std::uint8_t>(ParticleKind::Fluid);
}

template <int Dim>
double dist(const std::array<double, 3>& a, const double (&b)[3]) {
  double s = 0;
  for (int k = 0; k < Dim; ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(s);
}

template <int Dim, class Real>
void load(const Particles<Dim, Real>& p, std::size_t j, double (&x)[3]) {
  for (int k = 0; k < Dim; ++k) x[k] = static_cast<double>(p.x[j][k]);
}

// Shepard interpolation of the fields `get` (count values per particle) at `at`; NaN without fluid.
template <int Dim, class Real, class K, class Get>
void shepard(const Particles<Dim, Real>& p, const K& W, const std::array<double, 3>& at, int count, Get&& get,
             double* out) {
  double norm = 0, sum[3] = {0, 0, 0};
  for (std::size_t j = 0; j < p.size(); ++j) {
    if (!is_fluid(p, j)) continue;
    double xj[3] = {0, 0, 0};
    load(p, j, xj);
    const double w = W.W(dist<Dim>(at, xj));
    if (w <= 0) continue;
    const double vol = static_cast<double>(p.m[j]) / static_cast<double>(p.rho[j]);
    norm += vol * w;
    for (int c = 0; c < count; ++c) sum[c] += get(j, c) * vol * w;
  }
  for (int c = 0; c < count; ++c) out[c] = norm > 0 ? sum[c] / norm : kNaN;
}

// The level and layer probes: phi(y) on the vertical line through `at`, from the fluid in its column.
// level: the highest crossing of 1/2 (searched from the top down); layer: the first crossing from 1/2 or
// more to below it going up from `at`, where phi must reach 1/2 within one support of `at` (the water
// stands on `at`); water above a dry gap, a jet or spray in the air over the gauge, is not counted.
template <int Dim, class Real, class K>
double level(const Particles<Dim, Real>& p, const K& W, const std::array<double, 3>& at, double h,
             double spacing, bool layer) {
  constexpr int up = Dim - 1;
  std::vector<std::pair<std::array<double, 3>, double>> column;  // position, volume
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < p.size(); ++j) {
    if (!is_fluid(p, j)) continue;
    double xj[3] = {0, 0, 0};
    load(p, j, xj);
    double horizontal2 = 0;
    for (int k = 0; k < up; ++k) horizontal2 += (xj[k] - at[k]) * (xj[k] - at[k]);
    if (horizontal2 > h * h || xj[up] < at[up] - h) continue;
    column.push_back({{xj[0], xj[1], xj[2]}, static_cast<double>(p.m[j]) / static_cast<double>(p.rho[j])});
    top = std::max(top, xj[up]);
  }
  if (column.empty()) return 0;
  auto phi = [&](double y) {
    std::array<double, 3> q = at;
    q[up] = y;
    double s = 0;
    for (const auto& [x, vol] : column) {
      const double xj[3] = {x[0], x[1], x[2]};
      s += vol * W.W(dist<Dim>(q, xj));
    }
    return s;
  };
  const double step = spacing / 4;
  const double start = top + h;
  if (start <= at[up]) return 0;
  if (layer) {
    // From `at` up: wet within one support of it, then the first sample below 1/2 ends the search.
    const auto samples = static_cast<long>(std::ceil((start - at[up]) / step));
    bool wet = false;
    double y_below = at[up], phi_below = 0;
    for (long s = 0; s <= samples; ++s) {
      const double y = at[up] + double(s) * step;
      const double f = phi(y);
      if (!wet) {
        if (y > at[up] + h) return 0;
        wet = f >= 0.5;
      } else if (f < 0.5) {
        const double t = (phi_below - 0.5) / (phi_below - f);  // f < 1/2 <= phi_below
        return y_below + t * step - at[up];
      }
      y_below = y;
      phi_below = f;
    }
    return 0;
  }
  // From the top of the column down to `at`: the first sample at or above 1/2 ends the search.
  const auto samples = static_cast<long>(std::ceil((start - at[up]) / step));
  double y_above = start, phi_above = phi(start);
  for (long s = 1; s <= samples; ++s) {
    const double y = std::max(start - double(s) * step, at[up]);
    const double f = phi(y);
    if (f >= 0.5) {
      const double t = (f - 0.5) / (f - phi_above);  // phi_above < 1/2 <= f
      return y + t * (y_above - y) - at[up];
    }
    y_above = y;
    phi_above = f;
  }
  return 0;
}

}  // namespace

template <int Dim, class Real>
ProbeSampler<Dim, Real>::ProbeSampler(std::vector<Probe> probes, KernelKind kernel, double h, double spacing)
    : probes_(std::move(probes)), kernel_(kernel), h_(h), spacing_(spacing) {}

template <int Dim, class Real>
std::vector<double> ProbeSampler<Dim, Real>::sample(const Particles<Dim, Real>& p) const {
  std::vector<double> out;
  with_kernel<Dim, double>(kernel_, h_, [&](const auto& W) {
    for (const Probe& pr : probes_) {
      double v[3] = {kNaN, kNaN, kNaN};
      switch (pr.kind) {
        case ProbeKind::Pressure:
          shepard(
              p, W, pr.at, 1, [&](std::size_t j, int) { return static_cast<double>(p.p[j]); }, v);
          out.push_back(v[0]);
          break;
        case ProbeKind::Velocity:
          shepard(
              p, W, pr.at, Dim, [&](std::size_t j, int c) { return static_cast<double>(p.v[j][c]); }, v);
          out.insert(out.end(), v, v + Dim);
          break;
        case ProbeKind::Level:
        case ProbeKind::Layer:
          out.push_back(level(p, W, pr.at, h_, spacing_, pr.kind == ProbeKind::Layer));
          break;
      }
    }
    return 0;
  });
  return out;
}

template class ProbeSampler<2, float>;
template class ProbeSampler<2, double>;
template class ProbeSampler<3, float>;
template class ProbeSampler<3, double>;

}  // namespace cellsph
