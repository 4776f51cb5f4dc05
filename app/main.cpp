// cellsph: the command-line program. Sub-commands live one per file in app/.
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "cellsph/core/error.hpp"
#include "cellsph/distributed/communicator.hpp"
#include "commands.hpp"

namespace {

// An error's line and exit code. Across ranks, an error every rank meets alike (bad input, an agreed
// stop) is said once, by rank 0; one that a rank may meet alone (a write, memory, an internal error) is
// said by that rank, which then ends every rank (the others would wait for it in the next exchange).
int fail(const cellsph::distributed::Communicator& world, int code, const std::string& line,
         bool every_rank) {
  if (world.size() <= 1 || (every_rank && world.rank() == 0)) std::cerr << line << "\n";
  if (world.size() <= 1 || every_rank) return code;
  std::cerr << line << " (rank " << world.rank() << " of " << world.size() << "; ending every rank)\n";
  world.abort(code);
}

}  // namespace

// Exit codes (README.md "Exit codes"): 0 done, 1 internal error or out of memory, 2 bad input (scene,
// option, input file, checkpoint, a capacity limit the input goes beyond), 3 unstable simulation, 4 an
// output file could not be written, 130 / 143 a run stopped by SIGINT / SIGTERM (app/cmd_run.cpp).
int main(int argc, char** argv) {
  // MPI starts only where mpirun (or srun) started this process (docs/distributed.md).
  cellsph::distributed::MpiSession mpi(&argc, &argv);
  cellsph::app::program_name() = argc > 0 && argv[0] && *argv[0] ? argv[0] : "cellsph";
  CLI::App app{"cellsph: particle fluids (SPH) on the fastest exact neighbour search", "cellsph"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "cellsph 0.1.0");
  int result = 0;
  cellsph::app::register_neighbors(app, result);
  cellsph::app::register_bench(app, result);
  cellsph::app::register_run(app, result);
  cellsph::app::register_scenes(app, result);
  cellsph::app::register_doctor(app, result);
  const auto world = cellsph::distributed::world();
  try {
    // Across ranks (docs/distributed.md) `run` splits one simulation and `doctor` reports once; any other
    // command would run whole on every rank, into the same files. One message (rank 0), exit 2 on every
    // rank.
    const std::string command = argc > 1 ? argv[1] : "";
    if (world.size() > 1 && command != "run" && command != "doctor") {
      if (world.rank() == 0)
        std::cerr << "cellsph: error: started on " << world.size() << " MPI ranks: only `cellsph run` runs "
                  << "across ranks (and `cellsph doctor` reports them); start `cellsph " << command
                  << "` as one process (without mpirun)\n";
      return 2;
    }
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (world.rank() != 0) return e.get_exit_code() == 0 ? 0 : 2;
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const cellsph::InputError& e) {
    return fail(world, 2, std::string("cellsph: error: ") + e.what(), true);
  } catch (const cellsph::CapacityError& e) {
    // A limit of a data structure that this input goes beyond (key bits, bucket numbers): the user's
    // to work around (another method, another radius or spacing), so reported as bad input. Across
    // ranks, one rank's search may meet it alone.
    return fail(world, 2, std::string("cellsph: error: ") + e.what(), false);
  } catch (const cellsph::WriteError& e) {
    // An output file that could not be written (full disk, no permission, folder removed): the files
    // written before it and the last checkpoint stay valid (atomic writes), so a --resume continues.
    return fail(world, 4, std::string("cellsph: error: ") + e.what(), false);
  } catch (const cellsph::SimulationError& e) {
    // Across ranks the step's checks are agreed: every rank stops with the same message.
    return fail(world, 3, std::string("cellsph: simulation stopped: ") + e.what(), true);
  } catch (const std::bad_alloc&) {
    return fail(world, 1,
                "cellsph: error: out of memory: this needs more memory than the machine has free (for a run: "
                "fewer particles through a larger spacing, or a smaller neighbors.hash_table_size)",
                false);
  } catch (const std::exception& e) {
    return fail(world, 1, std::string("cellsph: internal error: ") + e.what(), false);
  }
  return result;
}
