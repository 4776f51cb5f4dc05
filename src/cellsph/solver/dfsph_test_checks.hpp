#pragma once
// Checks shared by the DFSPH and IISPH tests (solver/dfsph_test.cpp, solver/iisph_test.cpp): the host-
// emulated device against the CPU on test::DfsphDamBreak. Test code only (gtest).
#include <gtest/gtest.h>

#include <cstdint>

#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph::test {

// 40 steps of the dam break on the CPU and on the host-emulated device (the CUDA backend's code path over
// host memory): the same bits, time, iteration counts and divergence warm start. Returns the device's
// reorders.
inline std::uint64_t expect_device_gives_the_cpus_run(const DfsphDamBreak& d) {
  Simulation<2, double> cpu(d.cfg, d.particles);
  Simulation<2, double> dev(d.cfg, d.particles);
  dev.use_backend(Backend::HostDevice);
  for (int k = 0; k < 40; ++k) {
    cpu.step();
    dev.step();
  }
  EXPECT_TRUE(same_state(cpu.particles(), dev.particles()));
  EXPECT_EQ(cpu.time(), dev.time());
  EXPECT_EQ(cpu.dfsph_stats().density_iterations, dev.dfsph_stats().density_iterations);
  EXPECT_EQ(cpu.dfsph_stats().divergence_iterations, dev.dfsph_stats().divergence_iterations);
  EXPECT_EQ(cpu.solver_state().dfsph_kappa_v, dev.solver_state().dfsph_kappa_v);
  return dev.timings().reorders;
}

// A run started on the device resumes on the CPU from its state after 20 steps (particles, integrator and
// solver state, as a checkpoint carries them) and reaches the CPU's bits after 40, as if uninterrupted.
inline void expect_device_run_resumes_on_the_cpu(const DfsphDamBreak& d) {
  Simulation<2, double> cpu(d.cfg, d.particles);
  for (int k = 0; k < 40; ++k) cpu.step();
  Simulation<2, double> first(d.cfg, d.particles);
  first.use_backend(Backend::HostDevice);
  for (int k = 0; k < 20; ++k) first.step();
  Simulation<2, double> resumed(d.cfg, d.particles);
  resumed.restore(first.particles(), first.integrator_state(), "checkpoint", first.solver_state());
  for (int k = 20; k < 40; ++k) resumed.step();
  EXPECT_TRUE(same_state(resumed.particles(), cpu.particles()));
}

}  // namespace cellsph::test
