#pragma once
// Helpers shared by the command-line tests: a scratch folder, file I/O, and running the built
// `cellsph` (test::binary(), core/test_paths.hpp) capturing exit code, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cellsph/core/temp_dir_test_util.hpp"
#include "cellsph/core/test_paths.hpp"

namespace cellsph::test {

namespace fs = std::filesystem;

// The number of lines of s (newline characters).
inline std::size_t count_lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

inline void write_file(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
}

inline std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// The cells of a CSV text, row by row (no quoting: the files our runs write).
inline std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row(1);
  for (char c : text) {
    if (c == ',') {
      row.emplace_back();
    } else if (c == '\n') {
      rows.push_back(row);
      row.assign(1, "");
    } else {
      row.back() += c;
    }
  }
  return rows;
}

struct RunResult {
  int code = -1;
  std::string out;
  std::string err;
};

// Runs the built cellsph with `args` (already shell-quoted where needed).
inline RunResult run_cli(const TempDir& dir, const std::string& args) {
  const fs::path out = dir.path() / "..stdout", err = dir.path() / "..stderr";
  const std::string cmd = std::string("'") + cellsph::test::binary() + "' " + args + " >'" + out.string() +
                          "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

// Shell-quoted path (GCC 12 warns falsely, -Wrestrict, on "literal" + std::string temporaries).
inline std::string q(const fs::path& p) {
  std::string s = "'";
  s += p.string();
  s += '\'';
  return s;
}

// The CLI tests' scene: 72 particles falling in a box (a run of 0.1 s takes a fraction of a second),
// frames in every format, a checkpoint after every frame.
inline constexpr const char* kTiny = R"({
  "name": "tiny", "description": "test", "dimension": 2, "spacing": 0.05,
  "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.5}],
  "solver": {"model": "wcsph", "support": 0.1, "density_kernel": "cubic", "pressure_kernel": "cubic",
             "eos": {"kind": "tait", "stiffness": 20000, "gamma": 7, "clamp_negative": true}},
  "time": {"end": 0.1, "stepping": "courant", "dt_max": 0.002},
  "neighbors": {"method": "sorted-grid"},
  "fluids": [{"min": [0, 0], "max": [0.3, 0.6]}],
  "boundary": {"box": {"min": [0, 0], "max": [1, 1]}},
  "output": {"fps": 50, "formats": ["vtu", "ply", "csv"], "checkpoint_every": 1}
})";

}  // namespace cellsph::test
