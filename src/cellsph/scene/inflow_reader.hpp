#pragma once
// The scene keys `emitters` and `sinks` (docs/scenes.md, "Inflow and outflow") into SolverConfig::inflow
// (solver/emitters.hpp). Every error names the file, the key path and the value (InputError).
#include <cstdint>
#include <functional>

#include "cellsph/scene/json_reader.hpp"
#include "cellsph/solver/emitters.hpp"

namespace cellsph {

// Reads /emitters and /sinks of the scene's top-level reader `r` (both optional) into `out`; `phase_of`
// reads an emitter's "phase" key (a name or an index, as a fluid block's).
void read_inflow(JsonReader& r, int dim, double spacing,
                 const std::function<std::int32_t(JsonReader&)>& phase_of, Inflow& out);

}  // namespace cellsph
