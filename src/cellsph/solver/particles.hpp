#pragma once
// Struct-of-arrays particle storage. The one list of fields is for_each_field(): outputs,
// checkpoints and reordering are generated from it, so a new field is added in two places only
// (the member and its line in the list).
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "cellsph/core/vec.hpp"

namespace cellsph {

// Boundary particles carry in `m` their Akinci weight psi_b = rho0 V_b (their contribution to a fluid
// density), are never integrated and only interact with fluid particles.
enum class ParticleKind : std::uint8_t { Fluid = 0, Boundary = 1 };

template <int Dim, class Real>
struct Particles {
  using V = Vec<Dim, Real>;

  std::vector<V> x;                 // position [m]
  std::vector<V> v;                 // velocity [m/s]
  std::vector<V> f;                 // total force of the last evaluation [N]
  std::vector<Real> m;              // mass [kg]
  std::vector<Real> rho;            // density [kg/m^3]
  std::vector<Real> p;              // pressure [Pa]
  std::vector<Real> h;              // support length [m]
  std::vector<Real> color;          // interface colour value c_int (paper eq. 8c)
  std::vector<Real> mu;             // dynamic viscosity [Pa s]
  std::vector<std::int32_t> phase;  // phase index into the scene's phase table
  std::vector<std::int32_t> level;  // per-particle time-step level n_i (dt_i = dt_max / 2^n_i)
  std::vector<std::int64_t> tick;   // per-particle steps: state time in units of dt_max / 2^max_level
  std::vector<std::uint8_t> kind;   // ParticleKind: fluid (integrated) or boundary (static, Akinci 2012)

  // The field list. f(name, vector) for every field, in a fixed order.
  template <class Self, class F>
  static void for_each_field(Self& self, F&& fn) {
    fn(std::string_view("position"), self.x);
    fn(std::string_view("velocity"), self.v);
    fn(std::string_view("force"), self.f);
    fn(std::string_view("mass"), self.m);
    fn(std::string_view("density"), self.rho);
    fn(std::string_view("pressure"), self.p);
    fn(std::string_view("support"), self.h);
    fn(std::string_view("color"), self.color);
    fn(std::string_view("viscosity"), self.mu);
    fn(std::string_view("phase"), self.phase);
    fn(std::string_view("level"), self.level);
    fn(std::string_view("tick"), self.tick);
    fn(std::string_view("kind"), self.kind);
  }
  template <class F>
  void for_each_field(F&& fn) {
    for_each_field(*this, fn);
  }
  template <class F>
  void for_each_field(F&& fn) const {
    for_each_field(*this, fn);
  }

  [[nodiscard]] std::size_t size() const { return x.size(); }
  void resize(std::size_t n) {
    for_each_field([n](std::string_view, auto& field) { field.resize(n); });
  }
};

}  // namespace cellsph
