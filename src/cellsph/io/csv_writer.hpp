#pragma once
// CSV of the particles for scripts and spreadsheets. Header row
//   x,y[,z],vx,vy[,vz],density,pressure,phase
// then every other field of Particles::for_each_field() in list order (vectors as name_x,name_y[,name_z],
// scalars by name). Numbers are the shortest text that reads back bit-exactly (std::to_chars).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

// Which particles get a row; empty = all. The solver passes "is a fluid particle".
using CsvRowFilter = std::function<bool(std::size_t)>;

// The header row (without newline) for this field list.
template <int Dim, class Real>
std::string csv_header();

// Writes atomically. Rows are formatted in parallel (OpenMP) and written in particle order, so the
// file does not depend on the thread count.
template <int Dim, class Real>
void write_csv(const Particles<Dim, Real>& particles, const std::filesystem::path& path,
               const CsvRowFilter& keep = {});

}  // namespace cellsph
