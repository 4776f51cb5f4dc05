#pragma once
// A Simulation's checkpoint in the io/checkpoint.hpp format (`cellsph run` writes it as checkpoint.bin and
// reads it for --resume): the particles and the solver state are its fields, the simulated time and step
// count its header, and its user blob holds the rest of the integrator state and the caller's own bytes:
//
//   char[8] "CSPHSIM1" | u32 blob version | f64 last dt | u8 leap-frog started |
//   (version 2: u64 next particle id | u32 emitters e | e x f64 emitter advance) | u64 n + n bytes caller
//   data | (version 2:) u32 body count + per floating body its RigidBodyState (19 f64: x, q, v, w, a,
//   alpha)
//
// Version 2 adds the state of emitters (solver/emitters.hpp) and of floating bodies; version 1 files
// still read (no emitters ran: the next id follows the largest id, every emitter starts as at t = 0;
// its scenes had no floating bodies).
// Time and last dt are stored as double: exact for float and double runs, so a resume is bit for bit.
#include <filesystem>
#include <string>
#include <string_view>

#include "cellsph/solver/simulation.hpp"

namespace cellsph {

inline constexpr std::uint32_t kSimulationBlobVersion = 2;

// Writes atomically. `extra`: bytes the caller wants back on resume (the app's frame counter).
template <int Dim, class Real>
void write_simulation_checkpoint(const Simulation<Dim, Real>& sim, std::string_view extra,
                                 const std::filesystem::path& path);

// Reads and validates the file (everything read_checkpoint checks, then the blob), and restores `sim`
// (Simulation::restore: particle count, phases, kinds). Returns the caller's bytes. Throws InputError
// naming the file and what is wrong; `sim` is untouched on error.
template <int Dim, class Real>
std::string read_simulation_checkpoint(const std::filesystem::path& path, Simulation<Dim, Real>& sim);

// The caller's bytes of a simulation checkpoint of any dimension and precision, validated like
// read_simulation_checkpoint but restoring nothing: what a caller stored there may say how to build the
// Simulation to restore into (the Python module keeps the scene there). Throws InputError naming the file.
std::string read_simulation_checkpoint_extra(const std::filesystem::path& path);

}  // namespace cellsph
