#pragma once
// What the writers need to know about one element type of the particle field list, so every output
// format is generated from Particles::for_each_field() and a new field appears in all of them
// without touching the writers. A field is a std::vector<T> where T is a Vec<Dim,Real>, a floating
// point scalar or an integer scalar.
#include <cstdint>
#include <string_view>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph::io {

template <class T>
struct FieldType {
  static_assert(std::is_arithmetic_v<T>, "particle fields hold Vec, floating point or integer elements");
  using Scalar = T;
  static constexpr int components = 1;  // number of scalars stored per particle
  static constexpr bool is_vector = false;
  static Scalar get(const T& v, int) { return v; }
};

template <int Dim, class Real>
struct FieldType<Vec<Dim, Real>> {
  using Scalar = Real;
  static constexpr int components = Dim;
  static constexpr bool is_vector = true;
  static Scalar get(const Vec<Dim, Real>& v, int k) { return v[k]; }
};

template <class Vector>
using FieldOf = FieldType<typename std::remove_cvref_t<Vector>::value_type>;

// Every field must hold one element per particle; a writer indexing a shorter one would read past it.
template <class P>
void check_field_sizes(const P& particles) {
  particles.for_each_field([&](std::string_view name, const auto& field) {
    CELLSPH_CHECK(field.size() == particles.size(), "particle field '" << name << "' has " << field.size()
                                                                       << " elements for " << particles.size()
                                                                       << " particles");
  });
}

// VTK XML type name of a scalar type ("Float32", "Int32", ...).
template <class S>
constexpr std::string_view vtk_type_name() {
  if constexpr (std::is_same_v<S, float>)
    return "Float32";
  else if constexpr (std::is_same_v<S, double>)
    return "Float64";
  else if constexpr (std::is_same_v<S, bool>)
    return "UInt8";
  else if constexpr (std::is_integral_v<S> && std::is_signed_v<S>) {
    if constexpr (sizeof(S) == 1)
      return "Int8";
    else if constexpr (sizeof(S) == 2)
      return "Int16";
    else if constexpr (sizeof(S) == 4)
      return "Int32";
    else
      return "Int64";
  } else {
    static_assert(std::is_integral_v<S>, "unsupported field scalar");
    if constexpr (sizeof(S) == 1)
      return "UInt8";
    else if constexpr (sizeof(S) == 2)
      return "UInt16";
    else if constexpr (sizeof(S) == 4)
      return "UInt32";
    else
      return "UInt64";
  }
}

}  // namespace cellsph::io
