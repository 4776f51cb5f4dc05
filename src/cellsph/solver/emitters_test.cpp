// Inflow and outflow (solver/emitters.hpp, scene keys emitters and sinks; issue 13 item 3): the mass flux
// of an emitter against rho U A, a count bounded by a sink, ids unique and never reused, the same bits
// for 1 and 2 threads and through a checkpoint, and bad input refused naming the key and value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/checkpoint.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/io/simulation_checkpoint.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/emitters.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

constexpr std::uint8_t kFluid = static_cast<std::uint8_t>(ParticleKind::Fluid);

Scene<2, double> channel(const std::vector<std::string>& edits = {}) {
  std::string src;
  auto j = read_scene_json("channel-inflow", src);
  apply_scene_edits(j, edits, src);
  return load_scene<2, double>(j, src);
}

// The built-in channel: water enters at U = 2 m/s through a 0.1 m wide emitter at x = 0; a sink removes
// it beyond x = 0.6. Particle crossings of the plane x = 0.4 (net: forward minus backward, tracked by
// id) over t in [0.1, 0.6] s, times the particle mass, against rho U A: the count of a window is off by
// at most one lattice layer (10 of the 1000 particles of 100 layers: 1%), so 2% is honest.
TEST(Inflow, ChannelMassFluxMatchesRhoUAAndCountStaysBounded) {
  auto scene = channel();
  const double rho = 1000, U = 2, A = 0.1, plane = 0.4, t_from = 0.1, t_to = 0.6;
  Simulation<2, double> sim(scene.solver, scene.particles);
  const std::size_t fluid0 = sim.fluid_count();
  ASSERT_EQ(fluid0, 600u);
  std::vector<double> last_x;      // by id: x of the previous step (NaN: not seen)
  std::vector<std::uint8_t> gone;  // by id: removed
  std::uint32_t max_id = 0;
  for (const std::uint32_t id : sim.particles().id) max_id = std::max(max_id, id);
  auto track = [&](bool count, long& crossings) {
    const auto& p = sim.particles();
    std::vector<std::uint32_t> ids(p.id.begin(), p.id.end());
    std::sort(ids.begin(), ids.end());
    ASSERT_TRUE(std::adjacent_find(ids.begin(), ids.end()) == ids.end())
        << "duplicate id at t = " << sim.time();
    std::vector<std::uint8_t> present(last_x.size() > ids.back() + 1u ? last_x.size() : ids.back() + 1u, 0);
    if (last_x.size() < present.size()) {
      last_x.resize(present.size(), std::nan(""));
      gone.resize(present.size(), 0);
    }
    std::uint32_t new_max = max_id;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const std::uint32_t id = p.id[i];
      present[id] = 1;
      ASSERT_FALSE(gone[id]) << "id " << id << " was removed and is back";
      if (std::isnan(last_x[id])) {
        // A new particle: its id is above every id seen before (never reused).
        ASSERT_TRUE(sim.steps() == 0 || id > max_id) << "new id " << id << " not above " << max_id;
        new_max = std::max(new_max, id);
      } else if (count && p.kind[i] == kFluid) {
        if (last_x[id] < plane && p.x[i][0] >= plane) ++crossings;
        if (last_x[id] >= plane && p.x[i][0] < plane) --crossings;
      }
      last_x[id] = p.x[i][0];
    }
    for (std::size_t id = 0; id < last_x.size(); ++id)
      if (!present[id] && !std::isnan(last_x[id])) gone[id] = 1;
    max_id = new_max;
  };
  long crossings = 0;
  track(false, crossings);
  std::size_t max_fluid = 0;
  double t_a = -1, t_b = -1;
  while (sim.time() < t_to) {
    const double t0 = sim.time();
    sim.step();
    const bool count = t0 >= t_from;
    if (count && t_a < 0) t_a = t0;
    if (count) t_b = sim.time();
    track(count, crossings);
    max_fluid = std::max(max_fluid, sim.fluid_count());
  }
  ASSERT_GT(t_b - t_a, 0.45);
  const double m = sim.config().phases[0].mass;
  const double flux = double(crossings) * m / (t_b - t_a);
  EXPECT_NEAR(flux / (rho * U * A), 1.0, 0.02) << crossings << " crossings in " << t_b - t_a << " s";
  // Emitted: about U t / spacing layers of 10 (1200 particles by t = 0.6): without the sink the count
  // would have tripled; with it the channel holds its 600 within a layer or two.
  EXPECT_GT(max_id, 1500u);
  EXPECT_LE(max_fluid, fluid0 + 30);
  EXPECT_NEAR(double(sim.fluid_count()), double(fluid0), 30.0);
}

std::vector<Particles<2, double>> run_channel(int threads, int steps) {
  ScopedThreads t(threads);
  auto scene = channel({"/neighbors/reorder_every=7"});
  Simulation<2, double> sim(scene.solver, scene.particles);
  std::vector<Particles<2, double>> out;
  for (int s = 0; s < steps; ++s) sim.step();
  out.push_back(sim.particles());
  return out;
}

TEST(Inflow, SameBitsForOneAndTwoThreads) {
  const auto a = run_channel(1, 120), b = run_channel(2, 120);
  ASSERT_NE(a[0].size(), 0u);
  EXPECT_TRUE(test::same_state(a[0], b[0]));
}

// A checkpoint while the emitter is mid-layer and the sink has removed particles: the resumed run gives
// the uninterrupted run's bits, new ids included.
TEST(Inflow, ResumeIsBitIdenticalWithAnEmitterRunning) {
  ScopedThreads one(1);
  test::TempDir dir("inflow_ckpt");
  auto scene = channel();
  Simulation<2, double> full(scene.solver, scene.particles);
  std::uint32_t first_max = 0;
  for (const std::uint32_t id : full.particles().id) first_max = std::max(first_max, id);
  while (full.time() < 0.05) full.step();
  const auto st = full.integrator_state();
  ASSERT_EQ(st.emitter_advance.size(), 1u);
  ASSERT_GT(st.next_id, std::uint64_t{first_max} + 100);
  write_simulation_checkpoint(full, "", dir / "c.bin");
  for (int s = 0; s < 80; ++s) full.step();

  Simulation<2, double> resumed(scene.solver, scene.particles);
  read_simulation_checkpoint(dir / "c.bin", resumed);
  EXPECT_EQ(resumed.integrator_state().next_id, st.next_id);
  EXPECT_EQ(resumed.integrator_state().emitter_advance, st.emitter_advance);
  for (int s = 0; s < 80; ++s) resumed.step();
  EXPECT_EQ(resumed.time(), full.time());
  EXPECT_TRUE(test::same_state(full.particles(), resumed.particles()));
  EXPECT_EQ(resumed.integrator_state().next_id, full.integrator_state().next_id);
}

// The device step (the host-emulated device: the CUDA backend's code path over host memory) marks and holds
// the buffer with the CPU's passes and tests the sinks there; the Simulation emits and removes on the host
// and uploads again. The CPU's bits, ids and counts after several layers in and particles out, with Akinci
// walls and with dynamic walls (whose fixed wall-wall densities move with their slots); then a run
// started on the device resumes on the CPU with the uninterrupted CPU run's bits.
TEST(Inflow, HostDeviceStepsAreBitIdenticalToTheCpu) {
  for (const std::string walls : {"akinci", "dynamic"}) {
    SCOPED_TRACE(walls);
    auto scene = channel({"/boundary/model=" + walls});
    Simulation<2, double> cpu(scene.solver, scene.particles), dev(scene.solver, scene.particles);
    dev.use_backend(Backend::HostDevice);
    const std::size_t n0 = cpu.particles().size();
    const std::uint64_t id0 = cpu.integrator_state().next_id;
    std::set<std::size_t> counts;
    std::unique_ptr<Simulation<2, double>> resumed;
    for (int s = 1; s <= 90; ++s) {
      cpu.step();
      dev.step();
      if (s % 10 == 0) {
        ASSERT_TRUE(test::same_state(cpu.particles(), dev.particles())) << "after step " << s;
        counts.insert(dev.particles().size());
      }
      if (resumed) resumed->step();
      if (s == 40) {  // the device's particles and emitters' state into a CPU run, which continues
        resumed = std::make_unique<Simulation<2, double>>(scene.solver, scene.particles);
        resumed->restore(dev.particles(), dev.integrator_state(), "checkpoint", dev.solver_state());
      }
    }
    EXPECT_TRUE(test::same_state(resumed->particles(), cpu.particles()));
    EXPECT_EQ(cpu.time(), dev.time());
    EXPECT_EQ(cpu.fluid_count(), dev.fluid_count());
    const auto a = cpu.integrator_state(), b = dev.integrator_state();
    EXPECT_EQ(a.next_id, b.next_id);
    EXPECT_EQ(a.emitter_advance, b.emitter_advance);
    // Layers of 10 particles: at least 4 emitted; particles removed (fewer than n0 + emitted remain); the
    // count changed between the checks.
    EXPECT_GE(a.next_id, id0 + 40);
    EXPECT_LT(dev.particles().size(), n0 + (a.next_id - id0));
    EXPECT_GT(counts.size(), 1u);
  }
}

// A checkpoint of blob version 1 (before emitters) still reads: the next id follows the ids.
TEST(Inflow, CheckpointVersionOneStillReads) {
  test::TempDir dir("inflow_v1");
  auto scene = channel({"/emitters=[]", "/sinks=[]"});
  Simulation<2, double> sim(scene.solver, scene.particles);
  sim.step();
  std::string blob("CSPHSIM1", 8);
  auto put = [&](const auto& v) { blob.append(reinterpret_cast<const char*>(&v), sizeof v); };
  put(std::uint32_t{1});
  put(double(sim.last_dt()));
  put(std::uint8_t{0});
  put(std::uint64_t{0});
  write_checkpoint(sim.particles(), sim.solver_state(), CheckpointInfo{double(sim.time()), 1, blob},
                   dir / "v1.bin");
  Simulation<2, double> back(scene.solver, scene.particles);
  read_simulation_checkpoint(dir / "v1.bin", back);
  EXPECT_EQ(back.time(), sim.time());
  EXPECT_TRUE(test::same_state(back.particles(), sim.particles()));
}

// Outputs are written in ascending id order; with gaps left by a sink copy_in_id_order sorts.
TEST(Inflow, CopyInIdOrderSortsIdsWithGaps) {
  Particles<2, double> p;
  for (int k = 0; k < 4; ++k)
    add_particle<2, double>(p, Vec<2, double>{{double(k), 0}}, 0, ParticleKind::Fluid);
  p.id = {17, 3, 42, 5};
  EXPECT_FALSE(in_id_order(p));
  Particles<2, double> out;
  std::vector<std::uint32_t> from;
  copy_in_id_order(p, out, from);
  EXPECT_EQ(out.id, (std::vector<std::uint32_t>{3, 5, 17, 42}));
  EXPECT_EQ(from, (std::vector<std::uint32_t>{1, 3, 0, 2}));
  EXPECT_EQ(out.x[0][0], 1.0);
  EXPECT_TRUE(in_id_order(out));
}

void expect_input_error(const std::vector<std::string>& edits, const std::string& key,
                        const std::string& value) {
  try {
    channel(edits);
    ADD_FAILURE() << "no error for " << edits[0];
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(key), std::string::npos) << m;
    EXPECT_NE(m.find(value), std::string::npos) << m << " (value " << value << ")";
  }
}

TEST(Inflow, BadInputNamesTheKeyAndValue) {
  expect_input_error({"/emitters/0/normal=[0,0]"}, "/emitters/0/normal", "[0,0]");
  expect_input_error({"/emitters/0/size=-0.1"}, "/emitters/0/size", "-0.1");
  expect_input_error({"/emitters/0/velocity=-2"}, "/emitters/0/velocity", "-2");
  expect_input_error({"/emitters/0/start=1", "/emitters/0/end=0.5"}, "/emitters/0/end", "0.5");
  expect_input_error({"/sinks/0/max=[0.5,0.2]"}, "/sinks/0/max", "[0.5,0.2]");
  expect_input_error({"/emitters/0/shape=\"cone\""}, "/emitters/0/shape", "cone");
  expect_input_error({"/emitters/0/phase=\"oil\""}, "/emitters/0/phase", "oil");
  expect_input_error({"/emitters/0/size=1e6"}, "/emitters/0/size", "at most 10^7");
  // A library caller's phase without a mass: the emitter has nothing to give its particles.
  auto scene = channel();
  auto cfg = scene.solver;
  cfg.phases[0].mass = 0;
  try {
    Simulation<2, double> sim(cfg, scene.particles);
    ADD_FAILURE() << "an emitter without a mass";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("emitters[0].phase"), std::string::npos) << e.what();
  }
  // The config's own check (library callers): a zero normal.
  cfg = scene.solver;
  cfg.inflow.emitters[0].normal[0] = 0;
  try {
    cfg.validate();
    ADD_FAILURE() << "validate took a zero normal";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("emitters[0].normal"), std::string::npos) << e.what();
  }
}

// A fixed step far too long for the inflow (U dt of 5 spacings) stops the run naming the emitter, rather
// than emitting layers without bound.
TEST(Inflow, StepTooLongForTheEmitterStops) {
  auto scene = channel({"/time/stepping=\"fixed\"", "/time/dt=0.025"});
  Simulation<2, double> sim(scene.solver, scene.particles);
  try {
    sim.step();
    ADD_FAILURE() << "a step of 5 spacings went on";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("emitters[0]: velocity * dt = 0.05"), std::string::npos) << e.what();
  }
}

// The layer lattice: floor(size / spacing) particles across, centred, one spacing apart; a 3D disc keeps
// its square lattice's points within the radius (independently counted here).
TEST(Inflow, LayerLattice) {
  Emitter e;
  e.center[0] = 1;
  e.center[1] = 2;
  e.normal[0] = 0;
  e.normal[1] = 3;  // any length
  e.size[0] = 0.1;
  const auto f = emitter_frame<2, double>(e, 0.01, 0.02);
  ASSERT_EQ(f.layer.size(), 10u);
  EXPECT_NEAR(f.layer[0][0], 0.045, 1e-12);  // tangent (-1, 0): the first point at +0.045
  EXPECT_NEAR(f.layer[9][0], -0.045, 1e-12);
  EXPECT_NEAR(f.normal[1], 1.0, 1e-15);
  EXPECT_EQ(f.depth, 0.02);
  Emitter d;
  d.shape = EmitterShape::Disc;
  d.normal[0] = 0;
  d.normal[2] = 1;
  d.size[0] = 0.1;
  const auto g = emitter_frame<3, double>(d, 0.01, 0.02);
  std::size_t inside = 0;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const double x = (i - 4.5) * 0.01, y = (j - 4.5) * 0.01;
      inside += x * x + y * y <= 0.05 * 0.05 ? 1 : 0;
    }
  EXPECT_EQ(g.layer.size(), inside);
  for (const auto& q : g.layer) EXPECT_NEAR(q[2], 0.0, 1e-15);
}

}  // namespace
}  // namespace cellsph
