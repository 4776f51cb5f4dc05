// Diagnostic (target cellsph_wall_energy, built with the tests): the set-up of
// Walls/WallModels.WeaklyViscousBoxHoldsTenThousandSteps with energy bookkeeping per force term
// (docs/physics.md, "Scene stability"):
//   build/cellsph_wall_energy wcsph|paper akinci|adami|dynamic [courant 0.3] [steps 10000] [mu 0.5]
// Columns: E - E0, kinetic energy, work of the wall's own pressure term (Adami/dynamic: p_w / rho_w^2;
// Akinci: the mirrored p_b / rho_i^2), its split into the kernel-averaged and the hydrostatic part, the
// work of the fluid's own wall term (p_i / rho_i^2, conservative), of the viscosity (WCSPH only), and the
// residual E - E0 - W_wall - W_visc (integrator error when the other terms are conservative).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

using namespace cellsph;
using V2 = Vec<2, double>;

int main(int argc, char** argv) {
  const std::string model = argc > 1 ? argv[1] : "wcsph";
  const std::string walls = argc > 2 ? argv[2] : "adami";
  const double courant = argc > 3 ? std::atof(argv[3]) : 0.3;
  const int nsteps = argc > 4 ? std::atoi(argv[4]) : 10000;
  const double mu = argc > 5 ? std::atof(argv[5]) : 0.5;
  const auto wall_model = parse_wall_model(walls);
  if (!wall_model || (model != "wcsph" && model != "paper")) {
    std::fprintf(stderr,
                 "usage: cellsph_wall_energy wcsph|paper akinci|adami|dynamic [courant] [steps] [mu]\n");
    return 2;
  }
  const double H = test::ViscousBox::H, rho0 = test::ViscousBox::rho0, g = test::ViscousBox::g;
  test::ViscousBox box =
      test::weakly_viscous_box(model == "paper" ? Model::PaperMultiphase : Model::Wcsph, *wall_model, mu);
  SolverConfig<2, double>& cfg = box.cfg;
  cfg.time.courant = courant;
  if (const char* e = std::getenv("NOSLIP")) cfg.no_slip = std::atoi(e) != 0;
  Particles<2, double>& p = box.particles;
  const std::size_t fluid = box.fluid_count;
  const std::size_t n = p.size();
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, std::move(p));
  const double k = cfg.eos.stiffness, hs = cfg.support;
  const CubicSplineKernel<2, double> w(hs);
  const double mass = sim.total_mass(), mgH = mass * g * H;
  // Energy with densities summed at the current positions (the Hamiltonian of the WCSPH model).
  auto energy = [&](double* ke_out) {
    const auto& q = sim.particles();
    double e = 0, ke = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (q.kind[i] != 0) continue;
      double rho = 0;
      for (std::size_t j = 0; j < n; ++j) rho += q.m[j] * w.W2(distance2(q.x[i], q.x[j]));
      ke += q.m[i] * norm2(q.v[i]) / 2;
      e += q.m[i] * g * q.x[i][1];
      if (rho > rho0) e += q.m[i] * k * (std::log(rho / rho0) + rho0 / rho - 1) / rho0;
    }
    if (walls == "dynamic")
      for (std::size_t b = 0; b < n; ++b) {  // DBC walls store elastic energy too
        if (q.kind[b] == 0) continue;
        double rho = 0;
        for (std::size_t j = 0; j < n; ++j) rho += q.m[j] * w.W2(distance2(q.x[b], q.x[j]));
        if (rho > rho0) e += q.m[b] * k * (std::log(rho / rho0) + rho0 / rho - 1) / rho0;
      }
    if (ke_out) *ke_out = ke;
    return e + ke;
  };
  sim.step();
  const double e0 = energy(nullptr);
  double w_pb = 0, w_sh = 0, w_hy = 0, w_pi = 0, w_visc = 0, e_max = e0;
  std::vector<V2> x0(n), v0(n), xprev(n), dxs(n);
  bool have_prev = false;
  std::vector<double> frac(n, 0);
  std::printf("# model %s walls %s courant %g mu %g  mgH %.2f E0 %.3f\n", model.c_str(), walls.c_str(),
              courant, mu, mgH, e0);
  std::printf("# step t E-E0 KE W_pb(wall p_b term) W_shep W_hydro W_pi(wall p_i term) W_visc resid\n");
  const bool adami = cfg.wall_model != WallModel::Akinci;
  const double eps2 = 0.01 * hs * hs;
  try {
    for (int st = 1; st < nsteps; ++st) {
      {
        const auto& q = sim.particles();
        for (std::size_t i = 0; i < n; ++i) x0[i] = q.x[i], v0[i] = q.v[i];
      }
      sim.step();
      const auto& q = sim.particles();  // rho, p of x0 (walls too); x, v new
      // split each wall's p_b into the kernel average of p_f and the hydrostatic term (at x0)
      for (std::size_t b = fluid; b < n && adami; ++b) {
        double ps = 0, hy = 0;
        for (std::size_t f = 0; f < fluid; ++f) {
          const double rr = distance2(x0[b], x0[f]);
          if (rr > hs * hs) continue;
          const double wf = w.W2(rr);
          ps += q.p[f] * wf;
          hy += q.rho[f] * (x0[f][1] - x0[b][1]) * g * wf;
        }
        frac[b] = ps + hy != 0 ? ps / (ps + hy) : 0;
      }
      // central estimate of the displacement over which F(x_n) works, (x_{n+1} - x_{n-1}) / 2: unbiased for a
      // conservative force under symplectic Euler (F_n . (x_{n+1} - x_n) over-counts a stiff spring's work)
      for (std::size_t i = 0; i < fluid; ++i) dxs[i] = have_prev ? (q.x[i] - xprev[i]) * 0.5 : q.x[i] - x0[i];
      for (std::size_t i = 0; i < fluid; ++i) {
        const V2 dx = dxs[i];
        for (std::size_t b = fluid; b < n; ++b) {
          const V2 xib = x0[i] - x0[b];
          const double r2 = norm2(xib);
          if (r2 > hs * hs) continue;
          const V2 gw = w.gradW(xib);
          const double dwork = dot(gw, dx);
          w_pi += -q.m[i] * q.m[b] * q.p[i] / (q.rho[i] * q.rho[i]) * dwork;
          if (!adami) {
            const double pb = std::max(0.0, q.p[i] + q.rho[i] * g * (x0[i][1] - x0[b][1]));
            w_pb += -q.m[i] * q.m[b] * pb / (q.rho[i] * q.rho[i]) * dwork;
            w_hy += -q.m[i] * q.m[b] * (pb - q.p[i]) / (q.rho[i] * q.rho[i]) * dwork;
            w_sh += -q.m[i] * q.m[b] * q.p[i] / (q.rho[i] * q.rho[i]) * dwork;
          } else {
            const double pb = q.p[b], rb = q.rho[b];
            w_pb += -q.m[i] * q.m[b] * pb / (rb * rb) * dwork;
            if (pb > 0) {
              const double fr = frac[b];
              w_sh += -q.m[i] * q.m[b] * pb * fr / (rb * rb) * dwork;
              w_hy += -q.m[i] * q.m[b] * pb * (1 - fr) / (rb * rb) * dwork;
            }
          }
        }
        if (cfg.model == Model::Wcsph)
          for (std::size_t j = 0; j < fluid; ++j) {
            if (j == i) continue;
            const V2 xij = x0[i] - x0[j];
            const double r2 = norm2(xij);
            if (r2 > hs * hs) continue;
            const double qq = dot(v0[i] - v0[j], xij) / (r2 + eps2);
            const V2 f = w.gradW(xij) * (8 * mu * q.m[i] / q.rho[i] * q.m[j] / q.rho[j] * qq);
            w_visc += dot(f, dx);
          }
      }
      for (std::size_t i = 0; i < n; ++i) xprev[i] = x0[i];
      have_prev = true;
      if (st % 250 == 0 || st == nsteps - 1) {
        double ke = 0;
        const double e = energy(&ke);
        e_max = std::max(e_max, e);
        std::printf("%6d %.3f %9.3f %8.3f %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f\n", st, sim.time(), e - e0, ke,
                    w_pb, w_sh, w_hy, w_pi, w_visc, e - e0 - w_pb - w_visc);
        std::fflush(stdout);
      }
    }
  } catch (const SimulationError& e) {
    std::printf("# blew up: %s\n", e.what());
  }
  std::printf("# steps %llu max excess %.4f mgH\n", static_cast<unsigned long long>(sim.steps()),
              (e_max - e0) / mgH);
}
