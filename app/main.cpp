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
  try {
    // The distributed run is being built (issue 49): until every step runs across ranks, several ranks
    // would each run the whole scene into the same folder. One message (rank 0), exit 2 on every rank.
    const auto world = cellsph::distributed::world();
    if (world.size() > 1 && !(argc > 1 && std::string(argv[1]) == "doctor")) {
      if (world.rank() == 0)
        std::cerr
            << "cellsph: error: started on " << world.size()
            << " MPI ranks, but the run across ranks is not built yet (docs/distributed.md): start "
               "cellsph as one process (without mpirun, or mpirun -np 1); `cellsph doctor` reports MPI\n";
      return 2;
    }
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const cellsph::InputError& e) {
    std::cerr << "cellsph: error: " << e.what() << "\n";
    return 2;
  } catch (const cellsph::CapacityError& e) {
    // A limit of a data structure that this input goes beyond (key bits, bucket numbers): the user's
    // to work around (another method, another radius or spacing), so reported as bad input.
    std::cerr << "cellsph: error: " << e.what() << "\n";
    return 2;
  } catch (const cellsph::WriteError& e) {
    // An output file that could not be written (full disk, no permission, folder removed): the files
    // written before it and the last checkpoint stay valid (atomic writes), so a --resume continues.
    std::cerr << "cellsph: error: " << e.what() << "\n";
    return 4;
  } catch (const cellsph::SimulationError& e) {
    std::cerr << "cellsph: simulation stopped: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    std::cerr << "cellsph: error: out of memory: this needs more memory than the machine has free (for a "
                 "run: fewer particles through a larger spacing, or a smaller neighbors.hash_table_size)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cellsph: internal error: " << e.what() << "\n";
    return 1;
  }
  return result;
}
