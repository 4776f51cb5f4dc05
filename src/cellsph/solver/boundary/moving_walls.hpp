#pragma once
// Moving obstacles as a component of the Simulation (scene key wall_motion; the motions themselves in
// wall_motion.hpp): which wall particles move and how, kept by id from the particles the Simulation was
// built with (the scene's, so a resume built from the same scene has them and a checkpoint needs nothing
// of this); the moving walls' slots (boundary slots never change, rebuilt from the ids after a restore or a
// count change); and their position, velocity and acceleration at a time, a pure function of t and the
// initial position (MovingWallPass).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/solver/boundary/wall_motion.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

template <int Dim, class Real>
class MovingWalls {
 public:
  using V = Vec<Dim, Real>;

  // From the particles in their input order (positions, kinds, ids); InputError when the motions name
  // another count of particles or move a fluid particle.
  void init(const WallMotions& motions, const std::vector<V>& x, const std::vector<std::uint8_t>& kind,
            const std::vector<std::uint32_t>& id, std::uint8_t boundary_kind) {
    if (!motions.any()) return;
    const auto& of = motions.of_particle;
    const std::size_t n = x.size();
    if (of.size() != n)
      throw InputError("particles: the wall motions name " + std::to_string(of.size()) +
                       " particles, there are " + std::to_string(n));
    x0_of_id_.assign(n, V{});
    motion_of_id_.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      if (of[i] >= 0 && kind[i] != boundary_kind)
        throw InputError("particles: fluid particle " + std::to_string(i) + " is given a wall motion");
      x0_of_id_[id[i]] = x[i];
      motion_of_id_[id[i]] = of[i];
    }
  }

  // The moving walls among the boundary slots, from the particles' ids.
  void set_slots(const std::vector<std::uint32_t>& id, const IndexSet& boundary) {
    slots_.clear();
    x0_.clear();
    motion_.clear();
    if (motion_of_id_.empty()) return;
    for (const std::uint32_t b : boundary) {
      const std::int32_t m = motion_of_id_[id[b]];
      if (m < 0) continue;
      slots_.push_back(b);
      x0_.push_back(x0_of_id_[id[b]]);
      motion_.push_back(m);
    }
  }

  // Positions, velocities and accelerations of the moving walls at time t.
  void move(const WallMotions& motions, double t, V* x, V* v, V* wall_a) const {
    if (slots_.empty()) return;
    run_pass(slots_.size(), MovingWallPass<Dim, Real>{x, v, wall_a, slots_.data(), x0_.data(), motion_.data(),
                                                      motions.motions.data(), motions.rows.data(), t});
  }

  // The moving walls back at their initial positions (the dynamic walls' fixed density share).
  void to_initial(V* x) const {
    for (std::size_t k = 0; k < slots_.size(); ++k) x[slots_[k]] = x0_[k];
  }

  [[nodiscard]] bool any() const { return !slots_.empty(); }
  [[nodiscard]] const IndexSet& slots() const { return slots_; }
  [[nodiscard]] const std::vector<V>& initial_positions() const { return x0_; }
  [[nodiscard]] const std::vector<std::int32_t>& motions() const { return motion_; }

 private:
  std::vector<V> x0_of_id_;                 // per id: the initial position
  std::vector<std::int32_t> motion_of_id_;  // per id: its motion, -1 at rest (empty: nothing moves)
  IndexSet slots_;                          // per moving wall k: its slot, initial position and motion
  std::vector<V> x0_;
  std::vector<std::int32_t> motion_;
};

}  // namespace cellsph
