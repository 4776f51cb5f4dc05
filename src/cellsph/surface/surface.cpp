// The only translation unit that includes OpenVDB: its headers are heavy (tens of seconds to compile),
// so they stay out of surface.hpp and are compiled once, here.
#include "cellsph/surface/surface.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/task_arena.h>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/io/number_format.hpp"
#include "cellsph/physics/kernels.hpp"

namespace cellsph {

static_assert(std::endian::native == std::endian::little, "the PLY writer declares binary_little_endian");

SurfaceFormat parse_surface_format(std::string_view name) {
  if (name == "ply") return SurfaceFormat::Ply;
  if (name == "obj") return SurfaceFormat::Obj;
  throw InputError("surface format: expected \"ply\" or \"obj\", got \"" + std::string(name) + "\"");
}

std::string_view surface_format_extension(SurfaceFormat f) {
  return f == SurfaceFormat::Ply ? "ply" : "obj";
}

void validate(const SurfaceOptions& opt) {
  auto bad = [](const char* key, double v, const char* what) {
    throw InputError(std::string("surface option ") + key + " = " + io::number_text(v) + ": " + what);
  };
  if (!(std::isfinite(opt.voxel_size) && opt.voxel_size >= 0))
    bad("voxel_size", opt.voxel_size, "must be >= 0");
  if (!(std::isfinite(opt.voxel_fraction) && opt.voxel_fraction > 0))
    bad("voxel_fraction", opt.voxel_fraction, "must be > 0");
  if (!(opt.iso > 0 && opt.iso < 1)) bad("iso", opt.iso, "must lie in (0, 1)");
  if (!(std::isfinite(opt.support_scale) && opt.support_scale > 0))
    bad("support_scale", opt.support_scale, "must be > 0");
  if (opt.slab_voxels < 1 || opt.slab_voxels % 2 == 0)
    bad("slab_voxels", opt.slab_voxels, "must be an odd number >= 1");
  if (opt.threads < 0) bad("threads", opt.threads, "must be >= 0");
}

std::string surface_file_name(std::int32_t phase, std::size_t frame, SurfaceFormat format) {
  std::string num = std::to_string(frame);
  if (num.size() < 5) num.insert(0, 5 - num.size(), '0');
  return "surface_" + std::to_string(phase) + "_" + num + "." + std::string(surface_format_extension(format));
}

namespace {

using openvdb::Coord;
using openvdb::FloatGrid;

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// A sample further than this many voxels from the origin would overflow OpenVDB's 32-bit coordinates.
constexpr double kMaxIndex = 1 << 29;
// More voxels than this per kernel support is almost certainly a unit mistake, and would take very long.
constexpr double kMaxVoxelsPerSupport = 64;

template <int Dim, class Real>
struct Prepared {
  std::map<std::int32_t, std::vector<std::size_t>> phases;  // fluid particle indices per phase, ascending
  double voxel = 0;
};

template <int Dim, class Real>
Prepared<Dim, Real> prepare(const Particles<Dim, Real>& p, const SurfaceOptions& opt) {
  validate(opt);
  const std::size_t n = p.size();
  CELLSPH_CHECK(
      p.m.size() == n && p.rho.size() == n && p.h.size() == n && p.phase.size() == n && p.kind.size() == n,
      "particle fields of unequal length");
  Prepared<Dim, Real> out;
  double volume_sum = 0;
  double h_max = 0;
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.kind[i] != static_cast<std::uint8_t>(ParticleKind::Fluid)) continue;
    const double m = static_cast<double>(p.m[i]);
    const double rho = static_cast<double>(p.rho[i]);
    const double h = static_cast<double>(p.h[i]);
    bool finite = std::isfinite(m) && std::isfinite(rho) && std::isfinite(h);
    for (int k = 0; k < Dim; ++k) finite = finite && std::isfinite(static_cast<double>(p.x[i][k]));
    if (!finite || rho <= 0 || m <= 0 || h <= 0)
      throw SimulationError(
          "surface extraction: fluid particle " + std::to_string(i) +
          " has a non-finite position or a non-positive mass, density or support (m = " + io::number_text(m) +
          ", rho = " + io::number_text(rho) + ", h = " + io::number_text(h) + ")");
    volume_sum += m / rho;
    h_max = std::max(h_max, h);
    ++fluid;
    out.phases[p.phase[i]].push_back(i);
  }
  if (fluid == 0) return out;
  const double spacing = std::pow(volume_sum / static_cast<double>(fluid), 1.0 / Dim);
  out.voxel = opt.voxel_size > 0 ? opt.voxel_size : opt.voxel_fraction * spacing;
  if (h_max * opt.support_scale / out.voxel > kMaxVoxelsPerSupport)
    throw InputError("surface voxel size " + io::number_text(out.voxel) + " m is too small for the support " +
                     io::number_text(h_max * opt.support_scale) + " m (more than " +
                     io::number_text(kMaxVoxelsPerSupport) + " voxels per support)");
  for (const auto& [phase, idx] : out.phases)
    for (std::size_t i : idx)
      for (int k = 0; k < Dim; ++k)
        if (std::abs(static_cast<double>(p.x[i][k])) / out.voxel > kMaxIndex)
          throw SimulationError("surface extraction: fluid particle " + std::to_string(i) +
                                " at coordinate " + io::number_text(static_cast<double>(p.x[i][k])) +
                                " m lies too far from the origin for voxels of " +
                                io::number_text(out.voxel) + " m");
  return out;
}

// Samples phi = iso - c_k at voxel centres (index ijk at world position ijk * voxel). Inactive voxels hold
// the background iso, the exact value where no kernel reaches, so phi < 0 is inside the fluid as in a level
// set. The scatter runs over the particles in index order: the float sums, and so the mesh, are the same
// on every run and thread count.
template <int Dim, class Real>
FloatGrid::Ptr colour_field(const Particles<Dim, Real>& p, const std::vector<std::size_t>& idx, double voxel,
                            const SurfaceOptions& opt) {
  auto grid = FloatGrid::create(static_cast<float>(opt.iso));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
  auto acc = grid->getAccessor();
  const double inv = 1.0 / voxel;
  for (std::size_t i : idx) {
    const double hs = static_cast<double>(p.h[i]) * opt.support_scale;
    const Poly6Kernel<Dim, double> kernel(hs);
    const double w0 = static_cast<double>(p.m[i]) / static_cast<double>(p.rho[i]);
    std::array<int, 3> lo{0, 0, 0}, hi{0, 0, 0};
    std::array<double, 3> xc{0, 0, 0};
    for (int k = 0; k < Dim; ++k) {
      xc[k] = static_cast<double>(p.x[i][k]);
      lo[k] = static_cast<int>(std::ceil((xc[k] - hs) * inv));
      hi[k] = static_cast<int>(std::floor((xc[k] + hs) * inv));
    }
    for (int a = lo[0]; a <= hi[0]; ++a) {
      const double dx = a * voxel - xc[0];
      for (int b = lo[1]; b <= hi[1]; ++b) {
        const double dy = b * voxel - xc[1];
        for (int c = lo[2]; c <= hi[2]; ++c) {
          const double dz = Dim == 3 ? c * voxel - xc[2] : 0.0;
          const double r2 = dx * dx + dy * dy + dz * dz;
          if (r2 >= kernel.h2) continue;
          const Coord ijk(a, b, c);
          acc.setValue(ijk, acc.getValue(ijk) - static_cast<float>(w0 * kernel.W2(r2)));
        }
      }
    }
  }
  if constexpr (Dim == 2) {
    // Extrude the plane k = 0 into a slab: layers |k| <= half keep phi, the layer |k| = half + 1 holds
    // |phi|, so along z the sign changes exactly half-way between them (z = +-(half + 1/2) voxels) wherever
    // the plane is inside, and the slab's top and bottom are flat and the mesh closed.
    const int half = (opt.slab_voxels - 1) / 2;
    std::vector<std::pair<Coord, float>> plane;
    for (auto it = grid->cbeginValueOn(); it; ++it) plane.emplace_back(it.getCoord(), *it);
    for (const auto& [ijk, v] : plane) {
      for (int c = 1; c <= half; ++c) {
        acc.setValue(Coord(ijk.x(), ijk.y(), c), v);
        acc.setValue(Coord(ijk.x(), ijk.y(), -c), v);
      }
      acc.setValue(Coord(ijk.x(), ijk.y(), half + 1), std::abs(v));
      acc.setValue(Coord(ijk.x(), ijk.y(), -half - 1), std::abs(v));
    }
  }
  return grid;
}

// Quads (OpenVDB's dual mesher) to triangles cut along the shorter diagonal, unreferenced points dropped,
// and area-weighted vertex normals from the faces.
SurfaceMesh to_triangle_mesh(const std::vector<openvdb::Vec3s>& pts,
                             const std::vector<openvdb::Vec4I>& quads) {
  SurfaceMesh mesh;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> remap(pts.size(), kUnused);
  auto vertex = [&](std::uint32_t v) {
    if (remap[v] == kUnused) {
      remap[v] = static_cast<std::uint32_t>(mesh.points.size() / 3);
      for (int k = 0; k < 3; ++k) mesh.points.push_back(pts[v][k]);
    }
    return remap[v];
  };
  auto dist2 = [&](std::uint32_t a, std::uint32_t b) { return (pts[a] - pts[b]).lengthSqr(); };
  mesh.triangles.reserve(quads.size() * 6);
  for (const auto& q : quads) {
    std::array<std::uint32_t, 4> v{q[0], q[1], q[2], q[3]};
    for (auto& x : v) x = vertex(x);
    const bool diag02 = dist2(q[0], q[2]) <= dist2(q[1], q[3]);
    const std::array<std::uint32_t, 6> t =
        diag02 ? std::array<std::uint32_t, 6>{v[0], v[1], v[2], v[0], v[2], v[3]}
               : std::array<std::uint32_t, 6>{v[0], v[1], v[3], v[1], v[2], v[3]};
    mesh.triangles.insert(mesh.triangles.end(), t.begin(), t.end());
  }
  mesh.normals.assign(mesh.points.size(), 0.0f);
  auto P = [&](std::uint32_t v) {
    return openvdb::Vec3d(mesh.points[3 * v], mesh.points[3 * v + 1], mesh.points[3 * v + 2]);
  };
  std::vector<double> acc(mesh.points.size(), 0.0);
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 3) {
    const std::uint32_t a = mesh.triangles[t], b = mesh.triangles[t + 1], c = mesh.triangles[t + 2];
    const openvdb::Vec3d n = (P(b) - P(a)).cross(P(c) - P(a));  // twice the area, along the normal
    for (std::uint32_t v : {a, b, c})
      for (int k = 0; k < 3; ++k) acc[3 * v + k] += n[k];
  }
  for (std::size_t v = 0; v < acc.size(); v += 3) {
    const double len = std::sqrt(acc[v] * acc[v] + acc[v + 1] * acc[v + 1] + acc[v + 2] * acc[v + 2]);
    if (len > 0)
      for (int k = 0; k < 3; ++k) mesh.normals[v + k] = static_cast<float>(acc[v + k] / len);
  }
  return mesh;
}

SurfaceMesh mesh_phase(const FloatGrid& grid) {
  std::vector<openvdb::Vec3s> pts;
  std::vector<openvdb::Vec4I> quads;
  // With phi < 0 inside, OpenVDB winds the quads counter-clockwise seen from outside (the tests check
  // that the face normals point out of the fluid), the order PLY and OBJ readers expect.
  openvdb::tools::volumeToMesh(grid, pts, quads, 0.0);
  return to_triangle_mesh(pts, quads);
}

void write_ply_mesh(const SurfaceMesh& mesh, const std::filesystem::path& path) {
  std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment cellsph fluid surface\nelement vertex " +
      std::to_string(mesh.vertex_count()) +
      "\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nelement face " +
      std::to_string(mesh.triangle_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string body;
  body.reserve(mesh.vertex_count() * 24 + mesh.triangle_count() * 13);
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    float rec[6];
    for (int k = 0; k < 3; ++k) {
      rec[k] = mesh.points[3 * v + k];
      rec[3 + k] = mesh.normals[3 * v + k];
    }
    body.append(reinterpret_cast<const char*>(rec), sizeof(rec));
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    char rec[13];
    rec[0] = 3;
    for (int k = 0; k < 3; ++k) {
      const auto idx = static_cast<std::int32_t>(mesh.triangles[3 * t + k]);
      std::memcpy(rec + 1 + 4 * k, &idx, 4);
    }
    body.append(rec, sizeof(rec));
  }
  AtomicFile file(path, true);
  file.stream().write(header.data(), static_cast<std::streamsize>(header.size()));
  file.stream().write(body.data(), static_cast<std::streamsize>(body.size()));
  file.commit();
}

void write_obj_mesh(const SurfaceMesh& mesh, const std::filesystem::path& path) {
  std::string out = "# cellsph fluid surface\n";
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += "v";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      io::append_number(out, mesh.points[3 * v + k]);
    }
    out += '\n';
  }
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += "vn";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      io::append_number(out, mesh.normals[3 * v + k]);
    }
    out += '\n';
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    out += "f";
    for (int k = 0; k < 3; ++k) {
      const std::string i = std::to_string(mesh.triangles[3 * t + k] + 1);  // OBJ counts from 1
      out += ' ' + i + "//" + i;
    }
    out += '\n';
  }
  write_file_atomic(path, out);
}

}  // namespace

void write_surface_mesh(const SurfaceMesh& mesh, SurfaceFormat format, const std::filesystem::path& path) {
  if (format == SurfaceFormat::Ply)
    write_ply_mesh(mesh, path);
  else
    write_obj_mesh(mesh, path);
}

template <int Dim, class Real>
std::vector<PhaseSurface> extract_surfaces(const Particles<Dim, Real>& p, const SurfaceOptions& opt) {
  const auto prep = prepare(p, opt);
  std::vector<PhaseSurface> out;
  if (prep.phases.empty()) return out;
  initialize_openvdb();
  auto run = [&] {
    for (const auto& [phase, idx] : prep.phases) {
      const auto grid = colour_field(p, idx, prep.voxel, opt);
      out.push_back({phase, mesh_phase(*grid)});
    }
  };
  if (opt.threads > 0)
    tbb::task_arena(opt.threads).execute(run);
  else
    run();
  return out;
}

template <int Dim, class Real>
std::vector<std::filesystem::path> write_surfaces(const Particles<Dim, Real>& p, const SurfaceOptions& opt,
                                                  const std::filesystem::path& dir, std::size_t frame) {
  std::vector<std::filesystem::path> paths;
  for (const auto& s : extract_surfaces(p, opt)) {
    paths.push_back(dir / surface_file_name(s.phase, frame, opt.format));
    write_surface_mesh(s.mesh, opt.format, paths.back());
  }
  return paths;
}

#define CELLSPH_SURFACE_INSTANTIATE(D, R)                                                                   \
  template std::vector<PhaseSurface> extract_surfaces<D, R>(const Particles<D, R>&, const SurfaceOptions&); \
  template std::vector<std::filesystem::path> write_surfaces<D, R>(                                         \
      const Particles<D, R>&, const SurfaceOptions&, const std::filesystem::path&, std::size_t);
CELLSPH_SURFACE_INSTANTIATE(2, float)
CELLSPH_SURFACE_INSTANTIATE(2, double)
CELLSPH_SURFACE_INSTANTIATE(3, float)
CELLSPH_SURFACE_INSTANTIATE(3, double)
#undef CELLSPH_SURFACE_INSTANTIATE

std::string openvdb_version() {
  return openvdb::getLibraryVersionString();
}

}  // namespace cellsph
