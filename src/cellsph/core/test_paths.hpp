#pragma once
// Where the tests find their files and the program they run. Defined in test_paths_test.cpp, the one
// unit that is compiled with the checkout's absolute paths: every other test unit then compiles to the
// same object in any clone, so that the compiler cache (scripts/lib/configure_release.sh) reuses it.

namespace cellsph::test {

/// The checkout's root: data/, scenes/ and fuzz/ are read from here.
const char* source_dir();

/// The built `cellsph` program that the command-line tests run.
const char* binary();

}  // namespace cellsph::test
