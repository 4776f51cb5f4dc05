#pragma once
// Binary checkpoints: everything needed to continue a run bit for bit. The layout is generated from
// Particles::for_each_field(), so a new field is checkpointed without touching this code.
//
// Layout (little endian):
//   char[8] magic "CSPHCKPT" | u32 format version | u32 byte-order mark 0x01020304 | u32 Dim |
//   u32 sizeof(Real) | u64 particle count | f64 simulated time | u64 step count |
//   u64 n + n bytes user blob | u32 field count |
//   per field: u32 n + n bytes name | u32 element size | u64 element count | raw elements |
//   u64 checksum of all preceding bytes (64-bit FNV-1a over 8-byte words)
#include <cstdint>
#include <filesystem>
#include <string>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

inline constexpr std::uint32_t kCheckpointVersion = 1;

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

// Writes atomically.
template <int Dim, class Real>
void write_checkpoint(const Particles<Dim, Real>& particles, const CheckpointInfo& info,
                      const std::filesystem::path& path);

// Reads the header only; validates magic, version and byte order. Throws InputError naming the file.
CheckpointHeader read_checkpoint_header(const std::filesystem::path& path);

// Reads and validates everything (magic, version, byte order, Dim, precision, truncation, checksum,
// unknown / missing / duplicate fields, element sizes and counts) and replaces `particles`.
// Throws InputError naming the file and what is wrong; `particles` is untouched on error.
template <int Dim, class Real>
CheckpointInfo read_checkpoint(const std::filesystem::path& path, Particles<Dim, Real>& particles);

}  // namespace cellsph
