#pragma once
// Fluid surfaces per frame, the paper's "Interface Extraction" (end of section 3.3): the zero level of
// an implicit function built from the particles, meshed and written as one PLY or OBJ per phase.
//
// Per fluid phase k the SPH colour field (the Shepard-normalised indicator of paper eq. 8c)
//   c_k(x) = sum_{j fluid, phase_j = k} (m_j / rho_j) W_poly6(|x - x_j|, h_j)
// is sampled on a sparse voxel grid (OpenVDB) and the surface c_k = iso is meshed with OpenVDB's
// volume-to-mesh. Inside the fluid c_k is close to 1 and outside it is 0, so iso = 1/2 puts the surface
// half a particle spacing beyond the outermost particles, and two phases in contact meet on the same
// sheet (there c_A + c_B = 1). Boundary particles contribute nothing: the fluid's colour drops to 1/2
// where the wall begins, so a surface touching a wall closes along it. docs/surfaces.md has the details.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/solver/particles.hpp"

namespace cellsph {

enum class SurfaceFormat { Ply, Obj };

// "ply" or "obj"; throws InputError naming the value otherwise.
SurfaceFormat parse_surface_format(std::string_view name);
std::string_view surface_format_extension(SurfaceFormat f);  // "ply" or "obj"

struct SurfaceOptions {
  // Binary little-endian PLY (vertex x y z nx ny nz, triangle faces) or text OBJ (v, vn, f a//a ...).
  SurfaceFormat format = SurfaceFormat::Ply;
  // Voxel edge length [m]. 0: voxel_fraction * spacing, where spacing = (mean over the fluid particles
  // of m/rho)^(1/Dim), one value for all phases so that meshes of touching phases line up.
  double voxel_size = 0;
  double voxel_fraction = 0.5;
  // The level of the colour field that is the surface, in (0, 1).
  double iso = 0.5;
  // Kernel support used for the colour field, as a multiple of each particle's own support h. Above 1
  // smooths the surface (and costs (scale)^Dim more), below 1 makes it hug the particles.
  double support_scale = 1.0;
  // 2D runs: the contour is extruded into a closed slab this many voxels thick, centred on z = 0, so
  // the file is an ordinary closed triangle mesh that ParaView and Blender open.
  int slab_voxels = 3;
  // Threads OpenVDB's mesher may use (it runs on TBB, not OpenMP); 0: TBB's default (every core).
  // The result does not depend on it.
  int threads = 0;
};

// Checks the options; throws InputError naming the option and its value.
void validate(const SurfaceOptions& opt);

// The OpenVDB library this build meshes with, e.g. "10.0.1" (`cellsph doctor`).
std::string openvdb_version();

// One extracted mesh, in world coordinates (z = 0 is the 2D plane). Triangles are counter-clockwise
// seen from outside, and normals (unit, one per vertex) point out of the fluid.
struct SurfaceMesh {
  std::vector<float> points;             // x y z per vertex
  std::vector<float> normals;            // nx ny nz per vertex
  std::vector<std::uint32_t> triangles;  // three vertex indices per triangle
  [[nodiscard]] std::size_t vertex_count() const { return points.size() / 3; }
  [[nodiscard]] std::size_t triangle_count() const { return triangles.size() / 3; }
};

// The meshes of every fluid phase present in p (boundary particles excluded), ordered by phase.
struct PhaseSurface {
  std::int32_t phase = 0;
  SurfaceMesh mesh;
};
template <int Dim, class Real>
std::vector<PhaseSurface> extract_surfaces(const Particles<Dim, Real>& p, const SurfaceOptions& opt);

// Writes one file per fluid phase present, dir/surface_<phase>_<frame, 5 digits>.<ply|obj>, each atomically,
// and returns their paths ordered by phase. A phase without fluid particles gets no file; a phase whose
// colour field never reaches iso gets a valid empty mesh. Throws SimulationError if a fluid particle has a
// non-finite position or a non-positive density.
template <int Dim, class Real>
std::vector<std::filesystem::path> write_surfaces(const Particles<Dim, Real>& p, const SurfaceOptions& opt,
                                                  const std::filesystem::path& dir, std::size_t frame);

// The file name of one phase's mesh for a frame, e.g. surface_0_00042.ply.
std::string surface_file_name(std::int32_t phase, std::size_t frame, SurfaceFormat format);

void write_surface_mesh(const SurfaceMesh& mesh, SurfaceFormat format, const std::filesystem::path& path);

}  // namespace cellsph
