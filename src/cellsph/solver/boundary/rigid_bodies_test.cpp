// Floating rigid bodies (boundary/rigid_bodies.hpp, scene key `bodies`): mass properties against closed
// forms, Archimedes (a body of density 500 floats half submerged, one of 2000 sinks and rests on the
// floor), momentum of fluid plus body conserved without gravity, bad input (exit 2), the same bits for 1
// and 2 threads and through a checkpoint. Small 2D scenes (spacing 0.02 m), built from JSON as a user
// writes them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/test_paths.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/io/simulation_checkpoint.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/boundary/rigid_bodies.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

using json = nlohmann::json;
constexpr double kS = 0.02;  // spacing [m]

// A 1 m wide tank with water 0.4 m deep (WCSPH, Akinci walls, summation density, c0 ~ 20 m/s) and one
// body, at spacing `sp` (the support 2 sp).
json tank(const json& body, double sp = kS) {
  json j = json::parse(R"({
    "name": "body-test", "dimension": 2,
    "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.001}],
    "solver": {"model": "wcsph", "density_kernel": "cubic", "pressure_kernel": "cubic",
               "eos": {"kind": "ratio", "stiffness": 400000, "clamp_negative": true},
               "gravity": [0, -9.81], "artificial_viscosity": {"alpha": 0.05}},
    "time": {"stepping": "courant", "dt_max": 0.001, "courant": 0.3}
  })");
  j["spacing"] = sp;
  j["solver"]["support"] = 2 * sp;
  j["fluids"] = json::array({json{{"min", {0, 0}}, {"max", {1, 0.4}}}});
  j["boundary"]["walls"] = json{{"min", {0, 0}}, {"max", {1, 0.8}}, {"layers", 2}};
  j["domain"] = json{{"min", {-0.5, -0.5}}, {"max", {1.5, 1.5}}};
  j["bodies"] = json::array({body});
  return j;
}

json box_body(double x0, double y0, double x1, double y1, double density) {
  return json{{"box", {{"min", {x0, y0}}, {"max", {x1, y1}}}}, {"density", density}};
}

Scene<2, double> load(const json& j) {
  return load_scene<2, double>(j, "body-test.json");
}

// The area of the rectangle w x h centred at c, turned by `angle`, below the line y = level (the
// rectangle clipped by the half plane, Sutherland-Hodgman, then the shoelace formula).
double area_below(double cx, double cy, double angle, double w, double h, double level) {
  const double cs = std::cos(angle), sn = std::sin(angle);
  std::vector<std::array<double, 2>> poly;
  for (const auto& [u, v] :
       {std::array<double, 2>{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}})
    poly.push_back({cx + cs * u - sn * v, cy + sn * u + cs * v});
  std::vector<std::array<double, 2>> out;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const auto& a = poly[k];
    const auto& b = poly[(k + 1) % poly.size()];
    const bool ina = a[1] <= level, inb = b[1] <= level;
    if (ina) out.push_back(a);
    if (ina != inb) {
      const double t = (level - a[1]) / (b[1] - a[1]);
      out.push_back({a[0] + t * (b[0] - a[0]), level});
    }
  }
  double s = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const auto& a = out[k];
    const auto& b = out[(k + 1) % out.size()];
    s += a[0] * b[1] - b[0] * a[1];
  }
  return std::abs(s) / 2;
}

// The free surface away from the body in a tank of width w and spacing sp: per lattice column within
// 0.15 w of a side wall, its highest fluid particle plus half a spacing (each particle stands for its
// cell), averaged over the columns.
double water_level(const Simulation<2, double>& sim, double w = 1, double sp = kS) {
  const auto& p = sim.particles();
  const auto cols = static_cast<std::size_t>(std::lround(w / sp));
  std::vector<double> top(cols, -1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.x[i][0];
    if (p.kind[i] != 0 || !(x < 0.15 * w || x > 0.85 * w)) continue;
    const auto c = static_cast<std::size_t>(std::clamp(x / sp, 0.0, double(cols - 1)));
    top[c] = std::max(top[c], p.x[i][1]);
  }
  double sum = 0;
  int n = 0;
  for (const double t : top)
    if (t > 0) {
      sum += t + sp / 2;
      ++n;
    }
  return sum / n;
}

double angle_of(const RigidBodyState& s) {
  return 2 * std::atan2(s.q[3], s.q[0]);
}

TEST(RigidBodies, MassPropertiesMatchClosedForms) {
  // Box and ball against the lattice sum at a fine spacing (an independent quadrature).
  RigidBody box, lat;
  const double size[3] = {0.3, 0.1, 0};
  box_mass_properties(2, 500, size, box);
  EXPECT_DOUBLE_EQ(box.mass, 500 * 0.03);
  EXPECT_DOUBLE_EQ(box.inertia[8], box.mass * (0.09 + 0.01) / 12);
  std::vector<std::array<double, 3>> pts;
  const double h = 0.001;
  for (int i = 0; i < 300; ++i)
    for (int j = 0; j < 100; ++j) pts.push_back({(i + 0.5) * h, (j + 0.5) * h, 0});
  double c[3];
  lattice_mass_properties(2, 500, h, pts, lat, c);
  EXPECT_NEAR(lat.mass, box.mass, 1e-9);
  EXPECT_NEAR(c[0], 0.15, 1e-12);
  EXPECT_NEAR(lat.inertia[8], box.inertia[8], 1e-4 * box.inertia[8]);
  RigidBody ball;
  ball_mass_properties(3, 2000, 0.1, ball);
  EXPECT_NEAR(ball.mass, 2000 * 4.0 / 3.0 * M_PI * 1e-3, 1e-12);
  EXPECT_NEAR(ball.inertia[0], 0.4 * ball.mass * 0.01, 1e-15);
}

TEST(RigidBodies, SceneMakesTheBodyParticlesAndCarvesTheFluid) {
  const auto s = load(tank(box_body(0.35, 0.32, 0.65, 0.48, 500)));
  const auto& rb = s.solver.rigid_bodies;
  ASSERT_EQ(rb.bodies.size(), 1u);
  EXPECT_DOUBLE_EQ(rb.bodies[0].mass, 500 * 0.3 * 0.16);
  EXPECT_DOUBLE_EQ(rb.bodies[0].initial.x[0], 0.5);
  EXPECT_DOUBLE_EQ(rb.bodies[0].initial.x[1], 0.4);
  std::size_t in_body = 0;
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    const auto& x = s.particles.x[i];
    const bool inside = x[0] > 0.35 && x[0] < 0.65 && x[1] > 0.32 && x[1] < 0.48;
    if (s.particles.kind[i] == 0) {
      // No fluid particle closer than half a spacing to the body's surface.
      EXPECT_FALSE(x[0] > 0.35 - kS / 2 + 1e-9 && x[0] < 0.65 + kS / 2 - 1e-9 &&
                   x[1] > 0.32 - kS / 2 + 1e-9 && x[1] < 0.48 + kS / 2 - 1e-9)
          << "fluid at " << x[0] << ", " << x[1];
    }
    if (rb.of_particle[i] >= 0) {
      EXPECT_TRUE(inside);
      ++in_body;
    }
  }
  // Two layers of the 15 x 8 lattice: 15 * 8 - 11 * 4.
  EXPECT_EQ(in_body, 15u * 8u - 11u * 4u);
}

// Archimedes: a 0.3 x 0.16 m box of density 500, released with 44% of it below the water (its floating
// draft is 50%), heaves about its equilibrium with a period of ~0.85 s; the area below the free surface,
// averaged over 0.45-1.3 s (one period), is the submerged fraction.
double submerged_fraction(double sp) {
  auto s = load(tank(box_body(0.35, 0.33, 0.65, 0.49, 500), sp));
  Simulation<2, double> sim(s.solver, std::move(s.particles));
  double sum = 0;
  int n = 0;
  while (sim.time() < 1.3) {
    sim.step();
    if (sim.time() > 0.45 && sim.steps() % 5 == 0) {
      const auto& b = sim.body_states()[0];
      sum += area_below(b.x[0], b.x[1], angle_of(b), 0.3, 0.16, water_level(sim, 1, sp)) / (0.3 * 0.16);
      ++n;
    }
  }
  const double frac = sum / n;
  std::cout << "[ archimedes ] density 500, spacing " << sp << " m: submerged fraction " << frac
            << " (0.5 expected), steps " << sim.steps() << "\n";
  return frac;
}

// The body floats high by a fraction of a spacing (docs/physics.md, "Floating rigid bodies"): 0.466 at 8
// spacings across its height (0.02 m), outside the issue's 5%. At 16 spacings (0.01 m) the issue's 0.5
// within 5% holds, and the error has shrunk with the spacing (by at least a third), which is what an error
// of the particle discretisation does and a lost term or a wrong factor in the coupling does not.
TEST(RigidBodies, ArchimedesHalfSubmergedAtDensity500) {
  const double coarse = submerged_fraction(kS), fine = submerged_fraction(kS / 2);
  EXPECT_NEAR(coarse, 0.5, 0.1);
  EXPECT_NEAR(fine, 0.5, 0.025);
  EXPECT_LT(std::abs(fine - 0.5), 2.0 / 3.0 * std::abs(coarse - 0.5));
}

// A 0.2 x 0.1 m box of density 2000 released in the water sinks and lands on the floor; it does not sink
// through and stays: from 0.7 s on its bottom stays between the floor and one spacing above it (the fluid
// film under it drains slowly: it sits on one layer of fluid particles, 0.6-0.9 spacing up), and its mean
// height over 0.7-0.95 s and over 0.95-1.2 s differ by less than a tenth of a spacing. (Its speed jitters
// with the film's pressure noise: up to 0.14 m/s, printed.)
TEST(RigidBodies, HeavyBodySinksAndRestsOnTheFloor) {
  auto s = load(tank(box_body(0.4, 0.2, 0.6, 0.3, 2000)));
  Simulation<2, double> sim(s.solver, std::move(s.particles));
  double lo = 1, hi = -1, vmax = 0, first = 0, second = 0;
  int n1 = 0, n2 = 0;
  while (sim.time() < 1.2) {
    sim.step();
    if (sim.time() < 0.7) continue;
    const auto& b = sim.body_states()[0];
    const double bottom = b.x[1] - 0.05;
    lo = std::min(lo, bottom);
    hi = std::max(hi, bottom);
    vmax = std::max(vmax, std::abs(b.v[1]));
    if (sim.time() < 0.95) {
      first += bottom;
      ++n1;
    } else {
      second += bottom;
      ++n2;
    }
  }
  std::cout << "[ sink ] density 2000: bottom " << lo << " to " << hi << " m over 0.7-1.2 s, means "
            << first / n1 << " then " << second / n2 << ", vertical speed <= " << vmax << " m/s\n";
  EXPECT_GT(lo, -kS / 4);
  EXPECT_LT(hi, kS);
  EXPECT_NEAR(first / n1, second / n2, kS / 10);
}

// Contact alone: the same box dropped from 5 cm onto the dry part of the floor (the water in a corner
// block, which spreads but does not reach it by 0.3 s) lands and rests on it: bottom within a quarter spacing
// of the floor, level, still.
TEST(RigidBodies, DroppedBodyLandsAndRestsOnTheDryFloor) {
  json j = tank(box_body(0.7, 0.05, 0.9, 0.15, 2000));
  j["fluids"][0]["max"] = {0.1, 0.06};
  auto s = load(j);
  Simulation<2, double> sim(s.solver, std::move(s.particles));
  sim.run_until(0.3);
  const auto& b = sim.body_states()[0];
  const double bottom = b.x[1] - 0.05;
  std::cout << "[ land ] bottom " << bottom << " m, angle " << angle_of(b) << " rad, speed "
            << std::hypot(b.v[0], b.v[1]) << " m/s\n";
  EXPECT_NEAR(bottom, 0.0, kS / 4);
  EXPECT_NEAR(angle_of(b), 0.0, 0.01);
  EXPECT_LT(std::hypot(b.v[0], b.v[1]), 0.005);
}

// Without gravity and walls, a body moving through a blob of water: every force is a pair force (fluid
// pairs antisymmetric, the body's reaction the opposite of the same expression), so the total momentum
// changes only by rounding: each step adds dt sum_i f_i with |f_i| up to ~1e-3 M |V| / dt, and rounding of
// the ~400 updates a step at 1e-16 relative over 300 steps stays below 1e-10 M |V|.
TEST(RigidBodies, MomentumOfFluidAndBodyConservedWithoutGravity) {
  json j = json::parse(R"({
    "name": "body-momentum", "dimension": 2, "spacing": 0.02,
    "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.001}],
    "solver": {"model": "wcsph", "support": 0.04, "density_kernel": "cubic", "pressure_kernel": "cubic",
               "eos": {"kind": "ratio", "stiffness": 400000, "clamp_negative": true},
               "gravity": [0, 0], "artificial_viscosity": {"alpha": 0.05}},
    "boundary": {"slip": "no-slip"},
    "time": {"stepping": "courant", "dt_max": 0.001, "courant": 0.3},
    "fluids": [{"min": [0, 0], "max": [0.4, 0.4]}],
    "bodies": [{"box": {"min": [0.12, 0.14], "max": [0.24, 0.26]}, "density": 700, "velocity": [0.4, 0.1],
                "angular_velocity": 2}]
  })");
  auto s = load(j);
  const double M = s.solver.rigid_bodies.bodies[0].mass;
  Simulation<2, double> sim(s.solver, std::move(s.particles));
  auto total = [&] {
    const auto pf = sim.momentum();
    const auto& b = sim.body_states()[0];
    return std::array<double, 2>{pf[0] + M * b.v[0], pf[1] + M * b.v[1]};
  };
  const auto p0 = total();
  EXPECT_NEAR(p0[0], M * 0.4, 1e-15);
  const double scale = M * std::hypot(0.4, 0.1);
  for (int k = 0; k < 300; ++k) sim.step();
  const auto p1 = total();
  const auto& b = sim.body_states()[0];
  std::cout << "[ momentum ] body speed " << std::hypot(b.v[0], b.v[1]) << " (0.41 at start), drift "
            << std::hypot(p1[0] - p0[0], p1[1] - p0[1]) / scale << " of M |V0|\n";
  // The fluid took a share of the momentum (otherwise the test would not test the coupling).
  EXPECT_LT(std::hypot(b.v[0], b.v[1]), 0.98 * std::hypot(0.4, 0.1));
  EXPECT_NEAR(p1[0], p0[0], 1e-10 * scale);
  EXPECT_NEAR(p1[1], p0[1], 1e-10 * scale);
}

// The same in 3D (quaternion, world inertia tensor, gyroscopic term): a box spinning about a tilted axis
// thrown through a blob of water, 60 steps; the total momentum changes by rounding only, and the
// orientation stays a unit quaternion.
TEST(RigidBodies, MomentumConservedWithoutGravityIn3D) {
  json j = json::parse(R"({
    "name": "body-momentum-3d", "dimension": 3, "spacing": 0.04,
    "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.001}],
    "solver": {"model": "wcsph", "support": 0.08, "density_kernel": "cubic", "pressure_kernel": "cubic",
               "eos": {"kind": "ratio", "stiffness": 400000, "clamp_negative": true},
               "gravity": [0, 0, 0], "artificial_viscosity": {"alpha": 0.05}},
    "boundary": {"slip": "no-slip"},
    "time": {"stepping": "courant", "dt_max": 0.001, "courant": 0.3},
    "fluids": [{"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]}],
    "bodies": [{"box": {"min": [0.12, 0.12, 0.12], "max": [0.28, 0.24, 0.32]}, "density": 700,
                "velocity": [0.3, 0.1, -0.2], "angular_velocity": [1, 2, 3]}]
  })");
  auto s = load_scene<3, double>(j, "body-test-3d.json");
  const double M = s.solver.rigid_bodies.bodies[0].mass;
  EXPECT_NEAR(M, 700 * 0.16 * 0.12 * 0.2, 1e-12);
  Simulation<3, double> sim(s.solver, std::move(s.particles));
  auto total = [&] {
    const auto pf = sim.momentum();
    const auto& b = sim.body_states()[0];
    return std::array<double, 3>{pf[0] + M * b.v[0], pf[1] + M * b.v[1], pf[2] + M * b.v[2]};
  };
  const auto p0 = total();
  const double scale = M * std::sqrt(0.09 + 0.01 + 0.04);
  for (int k = 0; k < 60; ++k) sim.step();
  const auto p1 = total();
  const auto& b = sim.body_states()[0];
  const double speed = std::sqrt(b.v[0] * b.v[0] + b.v[1] * b.v[1] + b.v[2] * b.v[2]);
  std::cout << "[ momentum 3d ] body speed " << speed << " (0.374 at start), drift "
            << std::hypot(std::hypot(p1[0] - p0[0], p1[1] - p0[1]), p1[2] - p0[2]) / scale << " of M |V0|\n";
  EXPECT_LT(speed, 0.98 * std::sqrt(0.14));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(p1[a], p0[a], 1e-10 * scale);
  EXPECT_NEAR(b.q[0] * b.q[0] + b.q[1] * b.q[1] + b.q[2] * b.q[2] + b.q[3] * b.q[3], 1, 1e-14);
  // It turned: the quaternion left the identity.
  EXPECT_LT(b.q[0], 0.9999);
}

std::string body_load_error(const json& j) {
  try {
    auto s = load(j);
    Simulation<2, double> sim(s.solver, std::move(s.particles));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(RigidBodies, BadInputNamesKeyAndValue) {
  EXPECT_NE(body_load_error(tank(box_body(0.4, 0.5, 0.6, 0.6, 0))).find("/bodies/0/density"),
            std::string::npos);
  EXPECT_NE(body_load_error(tank(box_body(0.4, 0.5, 0.6, 0.6, -3))).find("-3"), std::string::npos);
  EXPECT_NE(body_load_error(tank(box_body(0.4, 0.5, 0.41, 0.6, 500))).find("thinner than two"),
            std::string::npos);
  EXPECT_NE(body_load_error(tank(box_body(0.4, 0.5, 0.3, 0.6, 500))).find("/bodies/0/box/max"),
            std::string::npos);
  EXPECT_NE(body_load_error(tank(json{{"density", 500}})).find("give a shape"), std::string::npos);
  json sphere = json{{"sphere", {{"center", {0.5, 0.6}}, {"radius", 0}}}, {"density", 500}};
  EXPECT_NE(body_load_error(tank(sphere)).find("radius"), std::string::npos);
  json typo = box_body(0.4, 0.5, 0.6, 0.6, 500);
  typo["densty"] = 3;
  EXPECT_NE(body_load_error(tank(typo)).find("densty"), std::string::npos);
  json paper = tank(box_body(0.4, 0.5, 0.6, 0.6, 500));
  paper["solver"]["model"] = "paper";
  paper["solver"].erase("density");
  paper["solver"].erase("density_diffusion");
  paper["solver"].erase("artificial_viscosity");
  EXPECT_NE(body_load_error(paper).find("floating bodies need the WCSPH model"), std::string::npos)
      << body_load_error(paper);
  // A device builds the body particles' rows out to h only: a contact distance of h or more is refused.
  auto s = load(tank(box_body(0.4, 0.5, 0.6, 0.6, 500)));
  s.solver.backend = Backend::HostDevice;
  s.solver.rigid_bodies.contact_distance = double(s.solver.support);
  try {
    Simulation<2, double> sim(s.solver, std::move(s.particles));
    ADD_FAILURE() << "the device backend took a contact distance of h";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("body_contact.distance below the support"), std::string::npos)
        << e.what();
  }
}

// Bits of every particle position and velocity and of the bodies' states.
template <class Sim>
std::vector<double> bits(const Sim& sim) {
  std::vector<double> out;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 2; ++a) {
      out.push_back(p.x[i][a]);
      out.push_back(p.v[i][a]);
    }
  for (const auto& b : sim.body_states())
    for (int a = 0; a < 3; ++a) {
      out.push_back(b.x[a]);
      out.push_back(b.v[a]);
      out.push_back(b.w[a]);
      out.push_back(b.q[a]);
    }
  return out;
}

// The floating box as it hits the water (forces, contact with nothing yet) and a heavy ball on the floor:
// 150 steps.
json two_bodies() {
  json j = tank(box_body(0.3, 0.41, 0.5, 0.51, 500));
  j["bodies"].push_back(json{{"sphere", {{"center", {0.75, 0.06}}, {"radius", 0.05}}}, {"density", 2000}});
  return j;
}

TEST(RigidBodies, SameBitsForOneAndTwoThreads) {
  auto run = [](int threads) {
    ScopedThreads t(threads);
    auto s = load(two_bodies());
    Simulation<2, double> sim(s.solver, std::move(s.particles));
    for (int k = 0; k < 150; ++k) sim.step();
    return bits(sim);
  };
  const auto one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t k = 0; k < one.size(); ++k) ASSERT_EQ(one[k], two[k]) << "entry " << k;
}

TEST(RigidBodies, ResumeIsBitForBit) {
  test::TempDir dir("bodies");
  auto s = load(two_bodies());
  const auto cfg = s.solver;
  const auto initial = s.particles;
  Simulation<2, double> a(cfg, s.particles);
  for (int k = 0; k < 80; ++k) a.step();
  write_simulation_checkpoint(a, "", dir / "ck.bin");
  for (int k = 0; k < 70; ++k) a.step();
  Simulation<2, double> b(cfg, initial);
  read_simulation_checkpoint(dir / "ck.bin", b);
  EXPECT_EQ(b.steps(), 80u);
  for (int k = 0; k < 70; ++k) b.step();
  const auto ba = bits(a), bb = bits(b);
  ASSERT_EQ(ba.size(), bb.size());
  for (std::size_t k = 0; k < ba.size(); ++k) ASSERT_EQ(ba[k], bb[k]) << "entry " << k;
}

// The device step (host-emulated: the CUDA backend's code path over host memory) runs the reaction and
// contact passes after the fluid's forces, the Simulation sums them per body in the CPU's order and takes
// the rigid step, the device places the body particles: the CPU's bits, bodies included, with Akinci and
// Adami walls (which read the bodies' accelerations); a checkpoint of the device run, read into a device
// run, continues with the same bits.
TEST(RigidBodies, HostDeviceStepsAreBitIdenticalToTheCpu) {
  for (const char* walls : {"akinci", "adami"}) {
    SCOPED_TRACE(walls);
    test::TempDir dir("bodies_device");
    json j = two_bodies();
    j["boundary"]["model"] = walls;
    auto s = load(j);
    auto dev_cfg = s.solver;
    dev_cfg.backend = Backend::HostDevice;
    Simulation<2, double> cpu(s.solver, s.particles), dev(dev_cfg, s.particles);
    for (int k = 0; k < 80; ++k) {
      cpu.step();
      dev.step();
    }
    write_simulation_checkpoint(dev, "", dir / "ck.bin");
    Simulation<2, double> resumed(dev_cfg, s.particles);
    read_simulation_checkpoint(dir / "ck.bin", resumed);
    for (int k = 80; k < 150; ++k) {
      cpu.step();
      dev.step();
      resumed.step();
    }
    const auto a = bits(cpu), b = bits(dev), c = bits(resumed);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], b[k]) << "entry " << k;
    ASSERT_EQ(a.size(), c.size());
    for (std::size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], c[k]) << "resumed, entry " << k;
    EXPECT_TRUE(test::same_state(cpu.particles(), dev.particles()));
    // The bodies moved (the box fell into the water): not a run of bodies at rest.
    EXPECT_GT(std::abs(cpu.body_states()[0].v[1]), 0.01);
  }
}

// Bodies with emitters and sinks: channel-inflow (water entering at 2 m/s, no gravity, a sink at the
// outlet) with a neutrally buoyant 0.04 m box in the stream, starting at rest. The particle count changes
// most steps (layers emitted, particles sunk), which moves the body particles' slots: the body stays
// rigid (every body particle keeps its distance to the body's centre), the flow carries it downstream,
// and 1 and 2 threads, the host-emulated device and a run resumed from a checkpoint give the same bits.
TEST(RigidBodies, BodiesRideWithEmittersAndSinks) {
  std::ifstream in(std::string(cellsph::test::source_dir()) + "/scenes/channel-inflow.json");
  json j = json::parse(in);
  j["bodies"] = json::array({box_body(0.1, 0.03, 0.14, 0.07, 1000)});
  auto s = load(j);
  const auto& of = s.solver.rigid_bodies.of_particle;
  // Each body particle's distance to the body's centre, by id.
  std::vector<double> r0(of.size(), -1);
  for (std::size_t i = 0; i < of.size(); ++i)
    if (of[i] >= 0) r0[i] = std::hypot(s.particles.x[i][0] - 0.12, s.particles.x[i][1] - 0.05);
  test::TempDir dir("bodies_inflow");
  auto run = [&](int threads, Backend backend, bool resume) {
    ScopedThreads t(threads);
    auto cfg = s.solver;
    cfg.backend = backend;
    Simulation<2, double> sim(cfg, s.particles);
    if (resume) read_simulation_checkpoint(dir / "ck.bin", sim);
    std::size_t lo = sim.particles().size(), hi = lo;
    while (sim.steps() < 300) {
      sim.step();
      if (sim.steps() == 150 && !resume && threads == 1 && backend == Backend::Cpu)
        write_simulation_checkpoint(sim, "", dir / "ck.bin");
      lo = std::min(lo, sim.particles().size());
      hi = std::max(hi, sim.particles().size());
    }
    return std::tuple{bits(sim), lo, hi, sim.body_states()[0], sim.particles()};
  };
  const auto [one, lo, hi, body, p] = run(1, Backend::Cpu, false);
  std::cout << "[ inflow ] " << lo << " to " << hi
            << " particles over 300 steps; the body at x = " << body.x[0] << " m moving at " << body.v[0]
            << " m/s\n";
  EXPECT_LT(lo, hi) << "the count never changed";
  EXPECT_GT(body.v[0], 0.1) << "the stream did not carry the body";
  EXPECT_LT(body.v[0], 2.2);
  std::size_t seen = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.id[i] >= r0.size() || r0[p.id[i]] < 0) continue;
    ++seen;
    EXPECT_NEAR(std::hypot(p.x[i][0] - body.x[0], p.x[i][1] - body.x[1]), r0[p.id[i]], 1e-12)
        << "id " << p.id[i];
  }
  EXPECT_EQ(seen,
            static_cast<std::size_t>(std::count_if(r0.begin(), r0.end(), [](double r) { return r >= 0; })));
  for (const auto& [threads, backend, resume] :
       {std::tuple{2, Backend::Cpu, false}, std::tuple{1, Backend::HostDevice, false},
        std::tuple{1, Backend::Cpu, true}}) {
    SCOPED_TRACE(std::to_string(threads) + " threads, " + (backend == Backend::Cpu ? "cpu" : "host device") +
                 (resume ? ", resumed" : ""));
    const auto other = std::get<0>(run(threads, backend, resume));
    ASSERT_EQ(one.size(), other.size());
    for (std::size_t k = 0; k < one.size(); ++k) ASSERT_EQ(one[k], other[k]) << "entry " << k;
  }
}

}  // namespace
}  // namespace cellsph
