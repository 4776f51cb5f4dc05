// libFuzzer entry of mesh_input.hpp (what is fuzzed and how: there, and docs/fuzzing.md).
#include <cstddef>
#include <cstdint>

#include "mesh_input.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  cellsph::fuzz::single_thread();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cellsph::fuzz::mesh_input(data, size);
  return 0;
}
