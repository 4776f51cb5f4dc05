// `cellsph bench ...`: PLACEHOLDER, to be written.
#include "commands.hpp"

namespace cellsph::app {
void register_bench(CLI::App& app, int& result) {
  auto* sub = app.add_subcommand("bench", "Benchmarks");
  sub->callback([&result] { result = 1; });
}
}  // namespace cellsph::app
