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

namespace {

using Kernel = CubicSplineKernel<2, double>;

// The box's constants every term uses.
struct Box {
  Kernel w;
  double hs, g, rho0, k;
  std::size_t fluid, n;
};

// The work of each force term so far.
struct Work {
  double pb = 0, sh = 0, hy = 0, pi = 0, visc = 0;
};

// The elastic energy of a particle of density rho (the Hamiltonian of the WCSPH model's EOS).
double elastic(const Box& b, double m, double rho) {
  return rho > b.rho0 ? m * b.k * (std::log(rho / b.rho0) + b.rho0 / rho - 1) / b.rho0 : 0;
}

// Energy with densities summed at the current positions; `dynamic_walls`: DBC walls store elastic energy.
double box_energy(const Particles<2, double>& q, const Box& b, bool dynamic_walls, double* ke_out) {
  auto density = [&](std::size_t i) {
    double rho = 0;
    for (std::size_t j = 0; j < b.n; ++j) rho += q.m[j] * b.w.W2(distance2(q.x[i], q.x[j]));
    return rho;
  };
  double e = 0, ke = 0;
  for (std::size_t i = 0; i < b.n; ++i) {
    if (q.kind[i] != 0) continue;
    ke += q.m[i] * norm2(q.v[i]) / 2;
    e += q.m[i] * b.g * q.x[i][1];
    e += elastic(b, q.m[i], density(i));
  }
  if (dynamic_walls)
    for (std::size_t i = 0; i < b.n; ++i)
      if (q.kind[i] != 0) e += elastic(b, q.m[i], density(i));
  if (ke_out) *ke_out = ke;
  return e + ke;
}

// Each wall's p_b split into the kernel average of p_f (the fraction `frac`) and the hydrostatic term (at
// x0).
void wall_pressure_fractions(const Particles<2, double>& q, const std::vector<V2>& x0, const Box& b,
                             std::vector<double>& frac) {
  for (std::size_t w = b.fluid; w < b.n; ++w) {
    double ps = 0, hy = 0;
    for (std::size_t f = 0; f < b.fluid; ++f) {
      const double rr = distance2(x0[w], x0[f]);
      if (rr > b.hs * b.hs) continue;
      const double wf = b.w.W2(rr);
      ps += q.p[f] * wf;
      hy += q.rho[f] * (x0[f][1] - x0[w][1]) * b.g * wf;
    }
    frac[w] = ps + hy != 0 ? ps / (ps + hy) : 0;
  }
}

// Fluid particle i's share of the wall terms' work over its displacement dx.
void add_wall_work(const Particles<2, double>& q, const std::vector<V2>& x0, const Box& b, bool adami,
                   const std::vector<double>& frac, std::size_t i, const V2& dx, Work& work) {
  for (std::size_t w = b.fluid; w < b.n; ++w) {
    const V2 xiw = x0[i] - x0[w];
    if (norm2(xiw) > b.hs * b.hs) continue;
    const double dwork = dot(b.w.gradW(xiw), dx);
    const double mm = q.m[i] * q.m[w];
    work.pi += -mm * q.p[i] / (q.rho[i] * q.rho[i]) * dwork;
    if (!adami) {
      const double pb = std::max(0.0, q.p[i] + q.rho[i] * b.g * (x0[i][1] - x0[w][1]));
      work.pb += -mm * pb / (q.rho[i] * q.rho[i]) * dwork;
      work.hy += -mm * (pb - q.p[i]) / (q.rho[i] * q.rho[i]) * dwork;
      work.sh += -mm * q.p[i] / (q.rho[i] * q.rho[i]) * dwork;
    } else {
      const double pb = q.p[w], rb = q.rho[w];
      work.pb += -mm * pb / (rb * rb) * dwork;
      if (pb > 0) {
        work.sh += -mm * pb * frac[w] / (rb * rb) * dwork;
        work.hy += -mm * pb * (1 - frac[w]) / (rb * rb) * dwork;
      }
    }
  }
}

// Fluid particle i's share of the viscosity's work (WCSPH's Morris-type term, mu) over dx.
void add_viscous_work(const Particles<2, double>& q, const std::vector<V2>& x0, const std::vector<V2>& v0,
                      const Box& b, double mu, std::size_t i, const V2& dx, Work& work) {
  const double eps2 = 0.01 * b.hs * b.hs;
  for (std::size_t j = 0; j < b.fluid; ++j) {
    if (j == i) continue;
    const V2 xij = x0[i] - x0[j];
    const double r2 = norm2(xij);
    if (r2 > b.hs * b.hs) continue;
    const double qq = dot(v0[i] - v0[j], xij) / (r2 + eps2);
    const V2 f = b.w.gradW(xij) * (8 * mu * q.m[i] / q.rho[i] * q.m[j] / q.rho[j] * qq);
    work.visc += dot(f, dx);
  }
}

}  // namespace

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
  const double H = test::ViscousBox::H;
  test::ViscousBox vbox =
      test::weakly_viscous_box(model == "paper" ? Model::PaperMultiphase : Model::Wcsph, *wall_model, mu);
  SolverConfig<2, double>& cfg = vbox.cfg;
  cfg.time.courant = courant;
  if (const char* e = std::getenv("NOSLIP")) cfg.no_slip = std::atoi(e) != 0;
  const Box b{Kernel(cfg.support), cfg.support,      test::ViscousBox::g,  test::ViscousBox::rho0,
              cfg.eos.stiffness,   vbox.fluid_count, vbox.particles.size()};
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, std::move(vbox.particles));
  const double mgH = sim.total_mass() * b.g * H;
  const bool dynamic_walls = walls == "dynamic", adami = cfg.wall_model != WallModel::Akinci;
  sim.step();
  const double e0 = box_energy(sim.particles(), b, dynamic_walls, nullptr);
  double e_max = e0;
  Work work;
  std::vector<V2> x0(b.n), v0(b.n), xprev(b.n);
  bool have_prev = false;
  std::vector<double> frac(b.n, 0);
  std::printf("# model %s walls %s courant %g mu %g  mgH %.2f E0 %.3f\n", model.c_str(), walls.c_str(),
              courant, mu, mgH, e0);
  std::printf("# step t E-E0 KE W_pb(wall p_b term) W_shep W_hydro W_pi(wall p_i term) W_visc resid\n");
  try {
    for (int st = 1; st < nsteps; ++st) {
      for (std::size_t i = 0; i < b.n; ++i) x0[i] = sim.particles().x[i], v0[i] = sim.particles().v[i];
      sim.step();
      const auto& q = sim.particles();  // rho, p of x0 (walls too); x, v new
      if (adami) wall_pressure_fractions(q, x0, b, frac);
      // central estimate of the displacement over which F(x_n) works, (x_{n+1} - x_{n-1}) / 2: unbiased for a
      // conservative force under symplectic Euler (F_n . (x_{n+1} - x_n) over-counts a stiff spring's work)
      for (std::size_t i = 0; i < b.fluid; ++i) {
        const V2 dx = have_prev ? (q.x[i] - xprev[i]) * 0.5 : q.x[i] - x0[i];
        add_wall_work(q, x0, b, adami, frac, i, dx, work);
        if (cfg.model == Model::Wcsph) add_viscous_work(q, x0, v0, b, mu, i, dx, work);
      }
      xprev = x0;
      have_prev = true;
      if (st % 250 == 0 || st == nsteps - 1) {
        double ke = 0;
        const double e = box_energy(q, b, dynamic_walls, &ke);
        e_max = std::max(e_max, e);
        std::printf("%6d %.3f %9.3f %8.3f %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f\n", st, sim.time(), e - e0, ke,
                    work.pb, work.sh, work.hy, work.pi, work.visc, e - e0 - work.pb - work.visc);
        std::fflush(stdout);
      }
    }
  } catch (const SimulationError& e) {
    std::printf("# blew up: %s\n", e.what());
  }
  std::printf("# steps %llu max excess %.4f mgH\n", static_cast<unsigned long long>(sim.steps()),
              (e_max - e0) / mgH);
}
