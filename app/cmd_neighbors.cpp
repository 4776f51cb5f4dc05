// `cellsph neighbors`: PLACEHOLDER, to be written.
#include "commands.hpp"

namespace cellsph::app {
void register_neighbors(CLI::App& app, int& result) {
  auto* sub = app.add_subcommand("neighbors", "Find all neighbours of a point set (CSV in, CSV out)");
  sub->callback([&result] { result = 1; });
}
}  // namespace cellsph::app
