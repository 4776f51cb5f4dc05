#pragma once
// Binary checkpoints: everything needed to continue a run bit for bit. The layout is generated from
// Particles::for_each_field() followed by SolverState::for_each_field() (solver/particles.hpp), so a new
// field of either is checkpointed without touching this code.
//
// Layout (little endian):
//   char[8] magic "CSPHCKPT" | u32 format version | u32 byte-order mark 0x01020304 | u32 Dim |
//   u32 sizeof(Real) | u64 particle count | f64 simulated time | u64 step count |
//   u64 n + n bytes user blob | u32 field count |
//   per field: u32 n + n bytes name | u32 element size | u64 element count | raw elements |
//   u64 checksum of all preceding bytes (64-bit FNV-1a over 8-byte words)
//
// Versions: 2 added the solver state's fields (dfsph_kappa_v). A version-1 file is still read: its solver
// state is 0, which is what the builds that wrote it resumed with.
#include <cstdint>
#include <filesystem>
#include <string>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

inline constexpr std::uint32_t kCheckpointVersion = 2;
inline constexpr std::uint32_t kCheckpointOldestVersion = 1;  // the oldest version read

struct CheckpointInfo {
  double time = 0;         // simulated time [s]
  std::uint64_t step = 0;  // steps taken so far
  std::string user;  // opaque caller data, stored verbatim (simulation_checkpoint.hpp: the integrator state)
};

// What a checkpoint holds before knowing Dim and Real: lets `--resume` pick the right instantiation.
struct CheckpointHeader {
  std::uint32_t version = 0;
  int dim = 0;
  int real_size = 0;  // sizeof(Real): 4 = float, 8 = double
  std::uint64_t count = 0;
  double time = 0;
  std::uint64_t step = 0;
};

// Writes atomically. Without `state`, the solver state's fields are written as 0.
template <int Dim, class Real>
void write_checkpoint(const Particles<Dim, Real>& particles, const SolverState<Dim, Real>& state,
                      const CheckpointInfo& info, const std::filesystem::path& path);
template <int Dim, class Real>
void write_checkpoint(const Particles<Dim, Real>& particles, const CheckpointInfo& info,
                      const std::filesystem::path& path);

// Reads the header only; validates magic, version and byte order. Throws InputError naming the file.
CheckpointHeader read_checkpoint_header(const std::filesystem::path& path);

// Reads and validates everything (magic, version, byte order, Dim, precision, truncation, checksum,
// unknown / missing / duplicate fields, element sizes and counts) and replaces `particles` and `state`.
// Throws InputError naming the file and what is wrong; `particles` and `state` are untouched on error.
// Without `state`, the solver state is read (and validated) but not returned.
template <int Dim, class Real>
CheckpointInfo read_checkpoint(const std::filesystem::path& path, Particles<Dim, Real>& particles,
                               SolverState<Dim, Real>& state);
template <int Dim, class Real>
CheckpointInfo read_checkpoint(const std::filesystem::path& path, Particles<Dim, Real>& particles);

}  // namespace cellsph
