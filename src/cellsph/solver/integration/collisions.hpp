#pragma once
// After the position update: the write-up's box and the paper's planes (boundaries.hpp) applied to each
// fluid particle, as one pass.
#include <cstddef>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/boundaries.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <int Dim, class Real>
struct BoxPlaneCollisionPass {
  ParticleView<Dim, Real> pv;
  bool box;  // the box is enabled
  Vec<Dim, Real> lo, hi;
  Real radius, damping;
  const Plane<Dim, Real>* planes;
  std::size_t plane_count;
  Real restitution, friction;

  CELLSPH_HD void operator()(std::size_t i) const {
    if (box) box_collision(pv.x[i], pv.v[i], lo, hi, radius, damping);
    for (std::size_t k = 0; k < plane_count; ++k)
      plane_collision(pv.x[i], pv.v[i], planes[k].normal, planes[k].offset, restitution, friction);
  }
};

template <int Dim, class Real>
BoxPlaneCollisionPass<Dim, Real> box_plane_collisions(const SolverConfig<Dim, Real>& cfg,
                                                      const ParticleView<Dim, Real>& pv) {
  return {pv,
          cfg.box.enabled,
          cfg.box.lo,
          cfg.box.hi,
          cfg.box.radius,
          cfg.box.damping,
          cfg.planes.data(),
          cfg.planes.size(),
          cfg.restitution,
          cfg.friction};
}

}  // namespace cellsph
