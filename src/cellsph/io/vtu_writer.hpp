#pragma once
// ParaView output: one VTK XML UnstructuredGrid (.vtu) per frame, every particle a vertex cell and
// every field of Particles::for_each_field() a PointData array (position is the grid's Points), plus a
// .pvd collection naming each frame's file and its simulated time so ParaView opens the whole run.
// Binary: raw appended data, header_type UInt64 (each block starts with its byte count), little endian.
#include <filesystem>
#include <string>
#include <vector>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

// Writes the particles to `path` atomically. `time` goes into the file as FieldData "TimeValue".
template <int Dim, class Real>
void write_vtu(const Particles<Dim, Real>& particles, double time, const std::filesystem::path& path);

// A frame written in pieces, one .vtu each (a run over several processes: one per rank), opens in ParaView
// as one data set through its .pvtu (PUnstructuredGrid): this writes it, atomically, listing `pieces`
// (file names relative to the .pvtu's folder) with the arrays of Particles<Dim, Real>; `like` gives their
// names and types (any particle set of the run: its values are not read).
template <int Dim, class Real>
void write_pvtu(const Particles<Dim, Real>& like, const std::vector<std::string>& pieces,
                const std::filesystem::path& path);

struct PvdEntry {
  double time = 0;
  std::string file;  // relative to the .pvd's folder
};

// The .pvd collection of a run. Every add() rewrites the whole file atomically, so a run killed at any
// moment leaves a valid collection listing the frames written so far.
class PvdWriter {
 public:
  explicit PvdWriter(std::filesystem::path path, std::vector<PvdEntry> entries = {});
  void add(double time, std::string file);
  void write() const;
  [[nodiscard]] const std::vector<PvdEntry>& entries() const { return entries_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<PvdEntry> entries_;
};

// Reads back a .pvd written by PvdWriter (for --resume). Throws InputError naming the file.
std::vector<PvdEntry> read_pvd(const std::filesystem::path& path);

}  // namespace cellsph
