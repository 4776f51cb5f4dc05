#pragma once
// The per-frame outputs of a run in one place: each selected format's file (frame_NNNNN.vtu/.ply/.csv),
// then the .pvd collection (if vtu) and frames.csv, both rewritten atomically after every frame. So
// `cellsph run` needs one call per frame, and a run killed at any moment leaves every listed frame
// complete.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cellsph/io/csv_writer.hpp"
#include "cellsph/io/frames_index.hpp"
#include "cellsph/io/vtu_writer.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

template <int Dim, class Real>
class FrameOutput {
 public:
  // Writes nothing: `dir` is created (if needed) by the first write(), so a run can build its outputs
  // before it has validated everything. `fluid` selects the CSV rows (empty = all particles; must be
  // thread-safe).
  FrameOutput(std::filesystem::path dir, OutputFormats formats, CsvRowFilter fluid = {},
              std::string pvd_name = "particles.pvd");

  // For --resume: reloads frames.csv and the .pvd and keeps the frames numbered below `next_frame`.
  // Reads only; the kept index is written with the next frame.
  void resume(std::size_t next_frame);

  // Writes frame number `frame` at simulated time `time`; returns the files written (absolute). The
  // particles are written in id order (particle k of every file has id k, whatever order the Simulation
  // keeps them in), so frames stay comparable row by row; the row filter is still asked with indices
  // into `particles`.
  std::vector<std::filesystem::path> write(const Particles<Dim, Real>& particles, std::size_t frame,
                                           double time);

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] const FramesIndex& index() const { return index_; }

 private:
  std::filesystem::path dir_;
  OutputFormats formats_;
  CsvRowFilter fluid_;
  FramesIndex index_;
  PvdWriter pvd_;
  bool dir_made_ = false;
  Particles<Dim, Real> ordered_;     // the particles in id order, when they are not already
  std::vector<std::uint32_t> from_;  // index in the caller's particles of each of ordered_
};

}  // namespace cellsph
