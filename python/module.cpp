// The `cellsph._cellsph` extension module: the neighbour search (neighbors_binding.cpp) and the simulator
// (simulation_binding.cpp) for NumPy. The package python/cellsph/__init__.py re-exports it and adds the
// pure-Python parts (read_frames, to_csr). Errors: InputError, CapacityError and argument errors become
// ValueError, SimulationError becomes cellsph.SimulationError (a RuntimeError).
#include <cmath>
#include <sstream>
#include <string>

#include "bindings.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"

namespace cellsph::python {

std::string repr_text(const py::handle& h) {
  try {
    return py::repr(h).cast<std::string>();
  } catch (const py::error_already_set&) {
    return "<object>";
  }
}

int check_threads(int threads, const char* name) {
  if (threads < 0)
    throw ArgumentError(std::string(name) + ": must be >= 1, or 0 for all cores; got " +
                        std::to_string(threads));
  return threads;
}

namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) {
  return py::str(a.dtype()).cast<std::string>();
}

// Any array-like as a NumPy array (a NumPy array itself is returned as it is).
py::array as_array(const py::handle& obj, const char* name) {
  py::array a = py::array::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw ArgumentError(std::string(name) + ": expected a NumPy array (or array-like of numbers), got " +
                        repr_text(obj));
  }
  return a;
}

template <class Real>
void check_finite(const py::array& a, const char* name) {
  const auto* v = static_cast<const Real*>(a.data());
  const auto rows = static_cast<std::size_t>(a.shape(0));
  const auto cols = static_cast<std::size_t>(a.ndim() == 2 ? a.shape(1) : 1);
  for (std::size_t i = 0; i < rows * cols; ++i) {
    if (!std::isfinite(v[i])) {
      std::ostringstream os;
      os << name << ": row " << i / cols << ", column " << i % cols << " is " << double(v[i])
         << " (coordinates must be finite)";
      throw ArgumentError(os.str());
    }
  }
}

}  // namespace

py::array points_array(const py::handle& points, const char* name) {
  py::array a = as_array(points, name);
  const bool f32 = py::isinstance<py::array_t<float>>(a);
  const bool f64 = py::isinstance<py::array_t<double>>(a);
  if (!f32 && !f64)
    throw ArgumentError(std::string(name) + ": dtype " + dtype_text(a) +
                        ", expected float32 or float64 (convert with .astype(numpy.float64))");
  if (a.ndim() != 2 || (a.shape(1) != 2 && a.shape(1) != 3))
    throw ArgumentError(std::string(name) + ": shape " + shape_text(a) + ", expected (n, 2) or (n, 3)");
  constexpr int kWanted =
      py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  if ((a.flags() & kWanted) != kWanted) a = py::array::ensure(a, kWanted);  // strided or unaligned: one copy
  if (f32)
    check_finite<float>(a, name);
  else
    check_finite<double>(a, name);
  return a;
}

py::array support_array(const py::handle& h, std::size_t n, bool is_float32, const char* name) {
  py::array a = as_array(h, name);
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw ArgumentError(std::string(name) + ": dtype " + dtype_text(a) + ", expected a float array");
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n)
    throw ArgumentError(std::string(name) + ": shape " + shape_text(a) + ", expected (" + std::to_string(n) +
                        ",): one support length per point");
  auto check = [&](auto typed) {
    using Real = typename decltype(typed)::value_type;
    auto* v = static_cast<const Real*>(typed.data());
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(v[i]) || v[i] < Real(0)) {
        std::ostringstream os;
        os << name << "[" << i << "] = " << double(v[i]) << ": support lengths must be finite and >= 0";
        throw ArgumentError(os.str());
      }
    return py::array(typed);
  };
  if (is_float32) return check(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a));
  return check(py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a));
}

double check_radius(double radius, const char* name) {
  if (!std::isfinite(radius) || !(radius > 0)) {
    std::ostringstream os;
    os << name << ": must be a finite number > 0, got " << radius;
    throw ArgumentError(os.str());
  }
  return radius;
}

}  // namespace cellsph::python

PYBIND11_MODULE(_cellsph, m) {
  namespace py = pybind11;
  using namespace cellsph::python;
  m.doc() = "cellsph: exact fixed-radius neighbour search (Cell Indexing) and the SPH simulator, for NumPy.";
  m.attr("__version__") = CELLSPH_VERSION;

  static py::exception<cellsph::SimulationError> simulation_error(m, "SimulationError", PyExc_RuntimeError);
  simulation_error.doc() =
      "The simulation became invalid (a non-finite state, a particle leaving the domain); the message names "
      "the step, the particle and the quantity.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ArgumentError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const cellsph::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const cellsph::CapacityError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const cellsph::SimulationError& e) {
      PyErr_SetString(simulation_error.ptr(), e.what());
    }
  });

  m.def("max_threads", &cellsph::max_threads,
        "The number of threads `threads=0` uses (all cores, or OMP_NUM_THREADS).");
  register_neighbors(m);
  register_simulation(m);
}
