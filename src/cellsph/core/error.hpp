#pragma once
// Error types. User-facing problems carry where they came from (file, row, column, key, value);
// internal invariants are CHECKed and stay on in release builds.
#include <sstream>
#include <stdexcept>
#include <string>

namespace cellsph {

// Bad input from a user: a file, a command-line value, a scene key. The CLI exits with code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A simulation that became unstable or invalid (NaN, particle escaping, ...). The message names the
// step, the particle and the quantity. The CLI exits with code 3.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An output file could not be written (no space, no permission, the folder removed under the run). The
// message names the file and the system's reason. The CLI exits with code 4.
class WriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A capacity of a data structure was exceeded (e.g. bits of a Cell Indexing key).
class CapacityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& msg);
}

}  // namespace cellsph

// Cheap internal invariant, kept in release builds.
#define CELLSPH_CHECK(cond, msg)                                                           \
  do {                                                                                     \
    if (!(cond)) {                                                                         \
      std::ostringstream cellsph_check_os_;                                                \
      cellsph_check_os_ << msg; /* NOLINT */                                               \
      ::cellsph::detail::check_failed(#cond, __FILE__, __LINE__, cellsph_check_os_.str()); \
    }                                                                                      \
  } while (false)
