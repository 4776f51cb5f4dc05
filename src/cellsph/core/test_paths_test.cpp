// The paths of test_paths.hpp. CMakeLists.txt gives this file alone CELLSPH_SOURCE_DIR and
// CELLSPH_BINARY (the fuzz harnesses give it CELLSPH_SOURCE_DIR only): the test programs link it.
#include "cellsph/core/test_paths.hpp"

namespace cellsph::test {

const char* source_dir() {
  return CELLSPH_SOURCE_DIR;
}

#ifdef CELLSPH_BINARY
const char* binary() {
  return CELLSPH_BINARY;
}
#endif

}  // namespace cellsph::test
