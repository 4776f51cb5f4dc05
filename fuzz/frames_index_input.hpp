#pragma once
// libFuzzer harness: what `cellsph run --resume` reads from an output folder besides the checkpoint:
// frames.csv (io/frames_index) and, for vtu runs, particles.pvd (io/vtu_writer's read_pvd), through
// FrameOutput::resume. The input is the frames.csv text, optionally followed by a line
// "=== particles.pvd ===" and the .pvd text. Both are written to a fresh folder, then the folder is resumed
// by a vtu+csv output at frame 3 (rows of later frames dropped). Bad input must end in InputError;
// anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "cellsph/io/frame_output.hpp"
#include "fuzz_util.hpp"

namespace cellsph::fuzz {

namespace detail_frames_index {

inline void write(const std::filesystem::path& p, std::string_view text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out) std::abort();
}

inline const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    auto d = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") /
             ("cellsph_frames_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

}  // namespace detail_frames_index

// One input of the harness (fuzz/frames_index_fuzz.cpp); also replayed by fuzz/regressions_test.cpp.
inline void frames_index_input(const std::uint8_t* data, std::size_t size) {
  using namespace detail_frames_index;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view sep = "\n=== particles.pvd ===\n";
  const auto cut = in.find(sep);
  const auto& dir = folder();
  write(dir / "frames.csv", in.substr(0, cut));
  std::filesystem::remove(dir / "particles.pvd");
  if (cut != std::string_view::npos) write(dir / "particles.pvd", in.substr(cut + sep.size()));
  try {
    FrameOutput<2, double> out(dir, parse_output_formats("vtu,csv"));
    out.resume(3);
  } catch (const InputError&) {
  }
}

}  // namespace cellsph::fuzz
