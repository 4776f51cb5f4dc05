// libFuzzer entry of frames_index_input.hpp (what is fuzzed and how: there, and docs/fuzzing.md).
#include <cstddef>
#include <cstdint>

#include "frames_index_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cellsph::fuzz::frames_index_input(data, size);
  return 0;
}
