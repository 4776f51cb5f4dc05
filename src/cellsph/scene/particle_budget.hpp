#pragma once
// The particles a scene asks for, counted before any is made (internal to scene/), so that a spacing too
// fine for this machine stops with the key and the count instead of hours of allocation or
// std::bad_alloc.
#include <string>

#include "cellsph/geometry/shape.hpp"
#include "cellsph/scene/json_reader.hpp"

namespace cellsph::scene_detail {

// About what one particle costs in a run: 256 bytes of fields and search structures, and 8 bytes for
// each pair within the search radius h (1 + skin) (a 4-byte entry in the search's lists and in the
// lists cut to h). For the 3D dam break (2.3 spacings, 51 pairs) that is 664 bytes; at 1.5e6
// particles (1e6 fluid) it peaked at 0.96 GB resident, 640 bytes a particle.
double pairs_per_particle(int dim, double search_radius_in_spacings);
double bytes_per_particle(double pairs);

// The limit is what the machine's memory holds at bytes_per_particle, and never above 2^31 (indices).
class ParticleBudget {
 public:
  // `radius`: the search radius h (1 + skin) in spacings, which sets the pairs each particle keeps.
  // `memory`: the bytes the particles may take (SceneLimits), 0 for this machine's memory.
  ParticleBudget(int dim, double spacing, double radius, double memory);

  // The lattice sites a shape's sampling walks (its bounding box): at most 64 per particle of the limit, so
  // that a thin shape in a huge box cannot take hours to sample.
  void take_sites(double sites, const JsonReader& r, const std::string& key, const std::string& what) const;

  // A lattice site's index along `axis` must fit its integer: fails at `key` if the object reaches `far`
  // metres from the origin, more than 2^50 spacings.
  void check_reach(double far, int axis, const JsonReader& r, const std::string& key,
                   const std::string& what) const;

  // Adds `count` particles made by the object at `key` of `r`; fails there if the total is too many.
  void take(double count, const JsonReader& r, const std::string& key, const std::string& what);

 private:
  static std::string number(double v);
  double spacing_, limit_ = 0, planned_ = 0;
  std::string why_, fix_;
};

// The particles a shape's sampling may make, counted before it runs: its volume (fluid) or a shell of
// `layers` spacings over its surface (walls), and the lattice it walks.
template <int Dim>
void budget_shape(ParticleBudget& budget, const geometry::Shape& s, double spacing, double margin,
                  double estimate, const JsonReader& r, const std::string& key, const std::string& what);

}  // namespace cellsph::scene_detail
