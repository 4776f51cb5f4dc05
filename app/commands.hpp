#pragma once
// Each sub-command registers itself on the CLI11 app and stores its exit code in `result` when it
// runs. Errors are thrown (InputError -> exit 2, SimulationError -> exit 3, WriteError -> exit 4) and
// mapped in main.cpp.
#include <string>

#include <CLI/CLI.hpp>

namespace cellsph::app {

void register_neighbors(CLI::App& app, int& result);
void register_bench(CLI::App& app, int& result);
void register_run(CLI::App& app, int& result);
void register_doctor(CLI::App& app, int& result);
void register_scenes(CLI::App& app, int& result);
// `cellsph bench steps` (cmd_bench_steps.cpp), added under `bench` by register_bench.
void add_bench_steps(CLI::App& bench, int& result);

// The program as it was invoked (argv[0]), for messages that print a command to paste.
inline std::string& program_name() {
  static std::string name = "cellsph";
  return name;
}

}  // namespace cellsph::app
