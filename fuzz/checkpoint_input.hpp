#pragma once
// libFuzzer harness: the checkpoint reader of `cellsph run --resume` (io/checkpoint for the format,
// io/simulation_checkpoint for the Simulation in it). The input is a checkpoint.bin. As the app does, the
// header picks the instantiation (read_checkpoint_header), then the file is read into a Simulation of a
// small scene of that dimension and precision (fuzz/scenes/), which then takes one step. Each input is
// read twice: as it is, and with its last 8 bytes replaced by the checksum of the rest, so that mutations
// reach the checks after the checksum's (Simulation::restore and the step). Bad input must end in
// InputError (or, for the step, SimulationError / CapacityError as for any run); anything else is a
// finding.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "cellsph/core/test_paths.hpp"
#include "cellsph/io/checkpoint.hpp"
#include "cellsph/io/checkpoint_impl.hpp"
#include "cellsph/io/simulation_checkpoint.hpp"
#include "cellsph/scene/scene.hpp"
#include "fuzz_util.hpp"

namespace cellsph::fuzz {

namespace detail_checkpoint {

template <int Dim, class Real>
const Scene<Dim, Real>& scene(const char* file) {
  static const Scene<Dim, Real> s = [file] {
    std::string source;
    const auto j = read_scene_json(std::string(cellsph::test::source_dir()) + "/fuzz/scenes/" + file, source);
    return load_scene<Dim, Real>(j, source);
  }();
  return s;
}

template <int Dim, class Real>
void resume(const std::filesystem::path& path, const char* scene_file) {
  const auto& s = scene<Dim, Real>(scene_file);
  Simulation<Dim, Real> sim(s.solver, s.particles);
  const std::string extra = read_simulation_checkpoint(path, sim);
  try {
    sim.step();
  } catch (const SimulationError&) {
  } catch (const CapacityError&) {
  }
}

inline void read(const std::filesystem::path& path) {
  try {
    const CheckpointHeader h = read_checkpoint_header(path);
    if (h.dim == 2 && h.real_size == 8) resume<2, double>(path, "checkpoint-2d.json");
    if (h.dim == 3 && h.real_size == 4) resume<3, float>(path, "checkpoint-3d-float.json");
    // Any other header: the mismatch messages of read_checkpoint.
    if (h.dim != 2 || h.real_size != 8) resume<2, double>(path, "checkpoint-2d.json");
  } catch (const InputError&) {
  }
}

}  // namespace detail_checkpoint

// One input of the harness (fuzz/checkpoint_fuzz.cpp); also replayed by fuzz/regressions_test.cpp.
inline void checkpoint_input(const std::uint8_t* data, std::size_t size) {
  using namespace detail_checkpoint;
  static MemFile file("checkpoint.bin");
  std::string bytes(reinterpret_cast<const char*>(data), size);
  file.set(bytes);
  read(file.path());
  if (bytes.size() >= 16) {
    const std::size_t body = bytes.size() - 8;
    const std::uint64_t sum = io::detail::checksum(bytes.data(), body);
    std::memcpy(bytes.data() + body, &sum, sizeof sum);
    file.set(bytes);
    read(file.path());
  }
}

}  // namespace cellsph::fuzz
