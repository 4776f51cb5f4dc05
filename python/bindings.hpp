#pragma once
// Shared pieces of the Python module's C++ side (python/*.cpp): argument checks that raise ValueError
// naming the argument and its value, and the registration functions of each part.
#include <cstdint>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace cellsph::python {

namespace py = pybind11;

// A user error in an argument: becomes ValueError in Python (module.cpp translates InputError the same way).
class ArgumentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// repr_text() of a Python object, for messages.
std::string repr_text(const py::handle& h);

// Thread counts: 0 = all cores, else >= 1.
int check_threads(int threads, const char* name = "threads");

// The points argument: any array-like of shape (n, 2) or (n, 3) and dtype float32 or float64, returned as a
// C-contiguous, aligned array of that dtype (the caller's own array when it already is one: no copy).
// Throws ArgumentError naming `name`, the shape or dtype, or the first non-finite coordinate.
py::array points_array(const py::handle& points, const char* name = "points");

// A per-point support length array of shape (n,): float dtype, finite, >= 0; converted to the points'
// dtype (`is_float32`).
py::array support_array(const py::handle& h, std::size_t n, bool is_float32, const char* name = "h");

// One radius: finite and > 0.
double check_radius(double radius, const char* name = "radius");

void register_neighbors(py::module_& m);
void register_simulation(py::module_& m);

}  // namespace cellsph::python
