#pragma once
// The one place that knows every model: the stepper of config.model (model_stepper.hpp) for a backend's
// step context. A new model is its stepper's file and one line here.
#include <memory>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/dfsph_stepper.hpp"
#include "cellsph/solver/models/iisph_stepper.hpp"
#include "cellsph/solver/models/model_stepper.hpp"
#include "cellsph/solver/models/paper_stepper.hpp"
#include "cellsph/solver/models/wcsph_stepper.hpp"

namespace cellsph {

template <int Dim, class Real, class Ctx>
std::unique_ptr<ModelStepper<Dim, Real, Ctx>> make_model_stepper(const SolverConfig<Dim, Real>& cfg) {
  switch (cfg.model) {
    case Model::PaperMultiphase:
      return std::make_unique<PaperStepper<Dim, Real, Ctx>>();
    case Model::Wcsph:
      return std::make_unique<WcsphStepper<Dim, Real, Ctx>>();
    case Model::Dfsph:
      return std::make_unique<DfsphStepper<Dim, Real, Ctx>>(cfg);
    case Model::Iisph:
      return std::make_unique<IisphStepper<Dim, Real, Ctx>>(cfg);
  }
  CELLSPH_CHECK(false, "model " << int(cfg.model) << " has no stepper");
  return nullptr;
}

}  // namespace cellsph
