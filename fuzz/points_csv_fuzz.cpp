// libFuzzer entry of points_csv_input.hpp (what is fuzzed and how: there, and docs/fuzzing.md).
#include <cstddef>
#include <cstdint>

#include "points_csv_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cellsph::fuzz::points_csv_input(data, size);
  return 0;
}
