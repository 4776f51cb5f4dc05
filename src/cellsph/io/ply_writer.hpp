#pragma once
// PLY point cloud of the particles for Blender and MeshLab: binary little endian, one vertex per
// particle with float x y z (z = 0 in 2D), vx vy vz, density, pressure and int phase.
#include <filesystem>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

// Writes atomically; `time` is recorded in a header comment ("comment time <seconds>").
template <int Dim, class Real>
void write_ply(const Particles<Dim, Real>& particles, double time, const std::filesystem::path& path);

}  // namespace cellsph
