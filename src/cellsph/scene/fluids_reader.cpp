// /fluids (docs/scenes.md, "fluids[k]"): the fluid at t = 0, boxes on the lattice and shaped volumes,
// each checked against the fluid before it and the walls, and kept half a spacing from shaped walls.
#include "cellsph/scene/scene_readers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/solver/initial.hpp"

namespace cellsph::scene_detail {

template <int Dim>
double count_fluid_particles(const nlohmann::json& j, double spacing) {
  double fluid = 0;
  if (j.contains("fluids") && j["fluids"].is_array())
    for (const auto& b : j["fluids"]) {
      if (!b.is_object() || !b.contains("min") || !b.contains("max")) continue;
      const auto &lo = b["min"], &hi = b["max"];
      if (!lo.is_array() || !hi.is_array() || lo.size() != Dim || hi.size() != Dim) continue;
      double n = 1;
      for (std::size_t a = 0; a < Dim; ++a)
        if (lo[a].is_number() && hi[a].is_number())
          n *= std::max(0.0, std::round((hi[a].get<double>() - lo[a].get<double>()) / spacing));
      fluid += n;
    }
  return fluid;
}

namespace {

// Whether a fluid particle at x keeps half a pitch of its lattice outside every shaped obstacle and inside
// some shaped container (the box walls' rule: fluid half a pitch from the wall's face). The pitch is the
// spacing, or less where a block's lattice is stretched to fit it (solver/initial.hpp): its sites next to a
// face it shares with a container are half that pitch from it (oil-glass at twice its spacing lost its
// whole bottom row, 12% of its oil, to half a spacing). The tolerance takes in a site computed in float:
// oil-glass's bottom row at twice its spacing, 0.0075 m above the glass's floor, is 0.0074999998 in float.
template <int Dim>
bool clear_of_walls(const geometry::P3& x, const Regions<Dim>& regions, double pitch) {
  const double gap = 0.5 * pitch * (1 - 1e-6);
  for (const auto& s : regions.solid_shapes) {
    const auto side = s.classify(x, gap);
    if (side.sign <= 0 || side.distance < gap) return false;
  }
  if (regions.container_shapes.empty()) return true;
  for (const auto& s : regions.container_shapes) {
    const auto side = s.classify(x, gap);
    if (side.sign < 0 && !(side.distance < gap)) return true;
  }
  return false;
}

// Fluid keeps this far (in spacings) from every wall particle made before it. A shaped wall's layers are
// sampled on the lattice of the scene's origin and the fluid on its block's (or shape's) lattice: where the
// spacing divides neither, a fluid site half a spacing inside a curved wall can sit 0.7 spacings from a wall
// particle (oil-glass at 1.37 times its spacing: 200 such sites, and one of them thrown up at 3.4 m/s within
// 0.05 s). At their own spacings, and at 1.2-2 times them, no site of any other built-in scene comes this
// close (measured: 0.98 spacings and more), so only such sites go.
constexpr double kWallClearance = 0.8;

// The wall (boundary) particles of p in cells of kWallClearance spacings, to find the fluid sites too close.
template <int Dim, class Real>
class WallParticleCells {
 public:
  WallParticleCells(const Particles<Dim, Real>& p, double spacing) : p_(p), cell_(kWallClearance * spacing) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] != static_cast<std::uint8_t>(ParticleKind::Fluid)) {
        std::array<long, 3> k{0, 0, 0};
        for (int a = 0; a < Dim; ++a) k[std::size_t(a)] = cell_of(double(p.x[i][a]));
        cells_[k].push_back(i);
      }
  }

  // Whether some wall particle lies closer than kWallClearance spacings to x.
  bool near(const geometry::P3& x) const {
    std::array<long, 3> c{0, 0, 0};
    for (int a = 0; a < Dim; ++a) c[std::size_t(a)] = cell_of(x[std::size_t(a)]);
    const long dz = Dim == 3 ? 1 : 0;
    for (long k = -dz; k <= dz; ++k)
      for (long j = -1; j <= 1; ++j)
        for (long i = -1; i <= 1; ++i) {
          const auto it = cells_.find({c[0] + i, c[1] + j, c[2] + k});
          if (it == cells_.end()) continue;
          for (const std::size_t q : it->second) {
            double r2 = 0;
            for (int a = 0; a < Dim; ++a) {
              const double d = double(p_.x[q][a]) - x[std::size_t(a)];
              r2 += d * d;
            }
            if (r2 < cell_ * cell_) return true;
          }
        }
    return false;
  }

 private:
  long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  const Particles<Dim, Real>& p_;
  double cell_;
  std::map<std::array<long, 3>, std::vector<std::size_t>> cells_;
};

// Adds the fluid particles at `xs`, a lattice of the given (smallest) pitch, that are clear of the shaped
// walls and of every wall particle (above); returns how many.
template <int Dim, class Real>
std::size_t add_fluid(Particles<Dim, Real>& p, const std::vector<geometry::P3>& xs,
                      const Regions<Dim>& regions, double spacing, double pitch, std::int32_t phase,
                      const Vec<Dim, Real>& vel, Real mass = 0) {
  std::vector<std::uint8_t> keep(xs.size(), 1);
  if (!regions.solid_shapes.empty() || !regions.container_shapes.empty()) {
    const WallParticleCells<Dim, Real> walls(p, spacing);
    parallel_for(xs.size(), [&](std::size_t i) {
      keep[i] = clear_of_walls(xs[i], regions, pitch) && !walls.near(xs[i]) ? 1 : 0;
    });
  }
  std::size_t added = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    if (!keep[i]) continue;
    Vec<Dim, Real> v;
    for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(xs[i][static_cast<std::size_t>(a)]);
    add_particle(p, v, phase, ParticleKind::Fluid, mass, vel);
    ++added;
  }
  return added;
}

// What every fluid block adds to: the particles, the budget that counts them (its errors name the block in
// /fluids, `list`), and the blocks read so far; and the walls it must keep clear of.
template <int Dim, class Real>
struct FluidTarget {
  JsonReader& list;
  double spacing;
  const PhaseTable& phases;
  const Regions<Dim>& regions;
  ParticleBudget& budget;
  Particles<Dim, Real>& p;
  FluidBlocks<Dim>& out;
};

// Fails at `e` unless the bounds `b` keep clear of the fluid blocks and shaped fluid volumes before it and
// of the obstacles, inside the boundary box; `why_blocks` says why two blocks must not overlap.
template <int Dim, class Real>
void check_fluid_bounds(const JsonReader& e, const Aabb<Dim>& b, const FluidTarget<Dim, Real>& t,
                        const std::string& why_blocks) {
  const double tol = 1e-9 * t.spacing;
  for (std::size_t o = 0; o < t.out.blocks.size(); ++o)
    if (overlap<Dim>(b, t.out.blocks[o], tol))
      e.fail_here("overlaps fluid block " + std::to_string(o) + " " + why_blocks);
  for (std::size_t o = 0; o < t.out.shape_bounds.size(); ++o)
    if (overlap<Dim>(b, t.out.shape_bounds[o], tol))
      e.fail_here("overlaps a shaped fluid volume before it (their bounds must not)");
  for (std::size_t o = 0; o < t.regions.solids.size(); ++o)
    if (overlap<Dim>(b, t.regions.solids[o], tol))
      e.fail_here("overlaps obstacle " + std::to_string(o) + " of /boundary/obstacles");
  if (t.regions.container && !inside<Dim>(b, *t.regions.container, tol))
    e.fail_here("lies (partly) outside the boundary box");
}

// Fluid volume `k` of /fluids, `e`, of the given shape: the lattice sites inside it that are clear of the
// shaped walls.
template <int Dim, class Real>
void add_fluid_volume(JsonReader& e, std::size_t k, const geometry::Shape& shape,
                      const FluidTarget<Dim, Real>& t) {
  const std::int32_t phase = t.phases.read_reference(e);
  const auto vel = to_vec<Dim, Real>(e.vector("velocity", Dim, filled<Dim>(0)));
  e.finish();
  Aabb<Dim> b{filled<Dim>(0), filled<Dim>(0)};
  for (std::size_t a = 0; a < Dim; ++a) {
    b.lo[a] = shape.lo()[a];
    b.hi[a] = shape.hi()[a];
  }
  check_fluid_bounds(e, b, t, "(the bounds of a shaped fluid volume must not)");
  budget_shape<Dim>(t.budget, shape, t.spacing, 0, 1.1 * shape.volume() / std::pow(t.spacing, Dim) + 8,
                    t.list, std::to_string(k), "this fluid volume");
  const std::size_t first = t.p.size();
  const std::vector<geometry::P3> xs = geometry::sample(shape, t.spacing, false, HUGE_VAL);
  if (add_fluid(t.p, xs, t.regions, t.spacing, t.spacing, phase, vel) == 0)
    e.fail_here("holds no particle: no lattice site of spacing " + std::to_string(t.spacing) +
                " lies inside it, half a spacing inside the containers and outside the obstacles");
  t.out.shape_bounds.push_back(b);
  t.out.shape_ranges.emplace_back(first, t.p.size());
  t.out.shape_phase.push_back(phase);
}

// The lattice of add_block in the block `b` (LatticeAxis), as points.
template <int Dim, class Real>
std::vector<geometry::P3> block_lattice(const Aabb<Dim>& b, const std::array<LatticeAxis, 3>& ax) {
  std::vector<geometry::P3> xs;
  xs.reserve(static_cast<std::size_t>(ax[0].n * ax[1].n * ax[2].n));
  for (long kk = 0; kk < ax[2].n; ++kk)
    for (long jj = 0; jj < ax[1].n; ++jj)
      for (long ii = 0; ii < ax[0].n; ++ii) {
        const long idx[3] = {ii, jj, kk};
        geometry::P3 x{0, 0, 0};
        for (std::size_t a = 0; a < Dim; ++a) x[a] = double(ax[a].site(static_cast<Real>(b.lo[a]), idx[a]));
        xs.push_back(x);
      }
  return xs;
}

// A fluid block ("min", "max") of /fluids, `e`: the lattice of add_block, less (with shaped walls) what is
// not clear of them.
template <int Dim, class Real>
void add_fluid_block(JsonReader& e, const FluidTarget<Dim, Real>& t) {
  const auto b = read_box<Dim>(e);
  const std::int32_t phase = t.phases.read_reference(e);
  const auto vel = to_vec<Dim, Real>(e.vector("velocity", Dim, filled<Dim>(0)));
  e.finish();
  const auto ax = lattice_of<Dim>(b, t.spacing, LatticeFit::Fluid);
  for (std::size_t a = 0; a < Dim; ++a)
    if (ax[a].n < 1)
      e.fail("max", "block holds no particle along axis " + std::to_string(a) + " (extent " +
                        std::to_string(b.hi[a] - b.lo[a]) + " < spacing " + std::to_string(t.spacing) + ")");
  check_fluid_bounds(e, b, t, "(particles would sit on top of each other)");
  t.out.blocks.push_back(b);
  t.out.phase.push_back(phase);
  t.out.pitch.push_back({ax[0].pitch, ax[1].pitch, ax[2].pitch});
  // A stretched lattice (the spacing does not divide the block) carries the phase's mass scaled by its
  // particles' volume, so its density is rho0; 0 elsewhere (the Simulation gives the phase's mass).
  const double factor = volume_factor<Dim>(ax, t.spacing);
  const Real mass = factor == 1 ? Real(0) : static_cast<Real>(t.phases.mass[std::size_t(phase)] * factor);
  if (t.regions.solid_shapes.empty() && t.regions.container_shapes.empty()) {
    const std::size_t first = t.p.size();
    add_block(t.p, to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), static_cast<Real>(t.spacing), phase,
              mass);
    for (std::size_t i = first; i < t.p.size(); ++i) t.p.v[i] = vel;
    return;
  }
  double pitch = t.spacing;
  for (std::size_t a = 0; a < Dim; ++a) pitch = std::min(pitch, double(ax[a].pitch));
  if (add_fluid(t.p, block_lattice<Dim, Real>(b, ax), t.regions, t.spacing, pitch, phase, vel, mass) == 0)
    e.fail_here("holds no particle half a spacing inside the containers and outside the obstacles");
}

}  // namespace

template <int Dim, class Real>
FluidBlocks<Dim> read_fluids(JsonReader& r, double spacing, const MeshFiles& files, const PhaseTable& phases,
                             const Regions<Dim>& regions, ParticleBudget& budget, Particles<Dim, Real>& p) {
  if (!r.has("fluids")) r.fail("fluids", "missing (a list of fluid blocks is required)");
  auto fr = r.child("fluids");
  const std::size_t nf = fr.array_size();
  if (nf == 0 && !r.has("emitters")) fr.fail_here("at least one fluid block (or an emitter) is needed");
  FluidBlocks<Dim> out;
  const FluidTarget<Dim, Real> target{fr, spacing, phases, regions, budget, p, out};
  for (std::size_t k = 0; k < nf; ++k) {
    auto e = fr.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    if (auto shape = read_shape<Dim>(e, spacing, files))
      add_fluid_volume(e, k, *shape, target);
    else {
      add_fluid_block(e, target);
      out.key.push_back(k);
    }
  }
  return out;
}

template double count_fluid_particles<2>(const nlohmann::json&, double);
template double count_fluid_particles<3>(const nlohmann::json&, double);

#define CELLSPH_FLUIDS_INSTANTIATE(D, R)                                                              \
  template FluidBlocks<D> read_fluids<D, R>(JsonReader&, double, const MeshFiles&, const PhaseTable&, \
                                            const Regions<D>&, ParticleBudget&, Particles<D, R>&);
CELLSPH_FLUIDS_INSTANTIATE(2, float)
CELLSPH_FLUIDS_INSTANTIATE(2, double)
CELLSPH_FLUIDS_INSTANTIATE(3, float)
CELLSPH_FLUIDS_INSTANTIATE(3, double)
#undef CELLSPH_FLUIDS_INSTANTIATE

}  // namespace cellsph::scene_detail
