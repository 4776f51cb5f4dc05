// /time (docs/scenes.md, "time"): end time and time stepping.
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

template <int Dim, class Real>
void read_time(JsonReader& r, SolverConfig<Dim, Real>& cfg, OutputSettings& out) {
  if (!r.has("time")) {
    cfg.time.mode = TimeStepping::Courant;
    return;
  }
  auto tr = r.child("time");
  out.end_time = tr.number("end", out.end_time, 1e-12, 1e9);
  cfg.time.mode =
      *parse_time_stepping(tr.choice("stepping", "courant", {"fixed", "courant", "per-particle"}));
  if (cfg.time.mode == TimeStepping::PerParticle && cfg.model != Model::PaperMultiphase)
    tr.fail("stepping", "\"per-particle\" needs the paper model (/solver/model = \"paper\")");
  cfg.time.max_level = static_cast<int>(tr.integer("max_level", cfg.time.max_level, 0, 30));
  cfg.time.correction = *parse_correction(tr.choice("correction", "exact", {"exact", "printed"}));
  cfg.time.dt = static_cast<Real>(tr.number("dt", double(cfg.time.dt), 1e-12, 10));
  cfg.time.dt_max = static_cast<Real>(tr.number("dt_max", double(cfg.time.dt_max), 1e-12, 10));
  cfg.time.dt_column = static_cast<Real>(tr.number("dt_column", double(cfg.time.dt_column), 0, 10));
  cfg.time.courant = static_cast<Real>(tr.number("courant", double(cfg.time.courant), 1e-6, 2));
  cfg.time.viscous = static_cast<Real>(tr.number("viscous", double(cfg.time.viscous), 1e-6, 10));
  cfg.time.force = static_cast<Real>(tr.number("force", double(cfg.time.force), 1e-6, 10));
  tr.finish();
}

#define CELLSPH_TIME_INSTANTIATE(D, R) \
  template void read_time<D, R>(JsonReader&, SolverConfig<D, R>&, OutputSettings&);
CELLSPH_TIME_INSTANTIATE(2, float)
CELLSPH_TIME_INSTANTIATE(2, double)
CELLSPH_TIME_INSTANTIATE(3, float)
CELLSPH_TIME_INSTANTIATE(3, double)
#undef CELLSPH_TIME_INSTANTIATE

}  // namespace cellsph::scene_detail
