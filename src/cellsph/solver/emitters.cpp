#include "cellsph/solver/emitters.hpp"

#include <algorithm>
#include <sstream>

namespace cellsph {

namespace {

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(9);
  os << v;
  return os.str();
}

}  // namespace

std::string inflow_config_error(const Inflow& in, int dim, std::size_t phases) {
  auto bad = [](const std::string& key, const std::string& value, const char* why) {
    return key + ": " + value + ": " + why;
  };
  if (in.any() && !(in.spacing > 0 && std::isfinite(in.spacing)))
    return bad("inflow.spacing", number_text(in.spacing), "must be > 0");
  for (std::size_t k = 0; k < in.emitters.size(); ++k) {
    const Emitter& e = in.emitters[k];
    const std::string key = "emitters[" + std::to_string(k) + "].";
    double n2 = 0;
    bool finite = true;
    for (int a = 0; a < dim; ++a) {
      n2 += e.normal[a] * e.normal[a];
      finite = finite && std::isfinite(e.normal[a]) && std::isfinite(e.center[a]);
    }
    if (!finite) return bad(key + "normal", "not finite", "the centre and normal must be finite");
    if (!(n2 > 0)) return bad(key + "normal", "zero vector", "must have a length > 0");
    const int sizes = e.shape == EmitterShape::Disc || dim == 2 ? 1 : 2;
    for (int a = 0; a < sizes; ++a)
      if (!(e.size[a] > 0 && std::isfinite(e.size[a])))
        return bad(key + "size", number_text(e.size[a]), "must be > 0");
    if (!(e.velocity >= 0 && std::isfinite(e.velocity)))
      return bad(key + "velocity", number_text(e.velocity), "must be >= 0");
    if (!std::isfinite(e.start)) return bad(key + "start", number_text(e.start), "must be finite");
    if (!(e.end >= e.start)) return bad(key + "end", number_text(e.end), "must not be before start");
    if (!(e.depth >= 0 && std::isfinite(e.depth)))
      return bad(key + "depth", number_text(e.depth), "must be >= 0");
    if (e.phase < 0 || static_cast<std::size_t>(e.phase) >= phases)
      return bad(key + "phase", std::to_string(e.phase), "is not in the phase table");
  }
  for (std::size_t k = 0; k < in.sinks.size(); ++k) {
    const Sink& s = in.sinks[k];
    for (int a = 0; a < dim; ++a)
      if (!(s.lo[a] <= s.hi[a]))
        return bad("sinks[" + std::to_string(k) + "].max", number_text(s.hi[a]),
                   ("is below min " + number_text(s.lo[a]) + " along axis " + std::to_string(a)).c_str());
  }
  return {};
}

template <int Dim, class Real>
EmitterFrame<Dim, Real> emitter_frame(const Emitter& e, double spacing, double support) {
  EmitterFrame<Dim, Real> f;
  double n[3] = {0, 0, 0}, len = 0;
  for (int a = 0; a < Dim; ++a) len += e.normal[a] * e.normal[a];
  len = std::sqrt(len);
  for (int a = 0; a < Dim; ++a) n[a] = e.normal[a] / len;
  // Tangents: 2D the normal turned by +90 degrees; 3D the axis least along n (lowest index on ties)
  // with its n part removed, then n x t1.
  double t[2][3] = {{0, 0, 0}, {0, 0, 0}};
  if (Dim == 2) {
    t[0][0] = -n[1];
    t[0][1] = n[0];
  } else {
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(n[a]) < std::abs(n[axis])) axis = a;
    double u[3] = {0, 0, 0};
    u[axis] = 1;
    double ul = 0;
    for (int a = 0; a < 3; ++a) {
      u[a] -= n[a] * n[axis];
      ul += u[a] * u[a];
    }
    ul = std::sqrt(ul);
    for (int a = 0; a < 3; ++a) t[0][a] = u[a] / ul;
    t[1][0] = n[1] * t[0][2] - n[2] * t[0][1];
    t[1][1] = n[2] * t[0][0] - n[0] * t[0][2];
    t[1][2] = n[0] * t[0][1] - n[1] * t[0][0];
  }
  for (int a = 0; a < Dim; ++a) {
    f.center[a] = static_cast<Real>(e.center[a]);
    f.normal[a] = static_cast<Real>(n[a]);
    f.velocity[a] = static_cast<Real>(n[a] * e.velocity);
    for (int k = 0; k < Dim - 1; ++k) f.tangent[k][a] = static_cast<Real>(t[k][a]);
  }
  f.spacing = static_cast<Real>(spacing);
  f.depth = static_cast<Real>(e.depth > 0 ? e.depth : support);
  f.disc = e.shape == EmitterShape::Disc && Dim == 3;
  // Cells along each tangent: floor(size / spacing), at least one (a tiny tolerance keeps 0.3 / 0.01 at 30).
  long cells[2] = {1, 1};
  const double width[2] = {e.size[0], f.disc ? e.size[0] : e.size[1]};
  for (int k = 0; k < Dim - 1; ++k) {
    cells[k] = std::max(1L, static_cast<long>(std::floor(width[k] / spacing * (1 + 1e-9))));
    f.half[k] = static_cast<Real>(width[k] / 2);
  }
  const double radius2 = e.size[0] * e.size[0] / 4;
  for (long j = 0; j < (Dim == 3 ? cells[1] : 1); ++j)
    for (long i = 0; i < cells[0]; ++i) {
      const double s[2] = {(double(i) + 0.5 - double(cells[0]) / 2) * spacing,
                           (double(j) + 0.5 - double(cells[1]) / 2) * spacing};
      if (f.disc && s[0] * s[0] + s[1] * s[1] > radius2) continue;
      Vec<Dim, Real> q{};
      for (int a = 0; a < Dim; ++a) {
        double c = 0;
        for (int k = 0; k < Dim - 1; ++k) c += s[k] * t[k][a];
        q[a] = static_cast<Real>(c);
      }
      f.layer.push_back(q);
    }
  return f;
}

template EmitterFrame<2, float> emitter_frame<2, float>(const Emitter&, double, double);
template EmitterFrame<2, double> emitter_frame<2, double>(const Emitter&, double, double);
template EmitterFrame<3, float> emitter_frame<3, float>(const Emitter&, double, double);
template EmitterFrame<3, double> emitter_frame<3, double>(const Emitter&, double, double);

}  // namespace cellsph
