#pragma once
// Implementation of the CSV writer, generic over the particle type so a test can prove that any field
// list is written. Include only from csv_writer.cpp and tests.
#include <algorithm>
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/csv_writer.hpp"
#include "cellsph/io/field_types.hpp"
#include "cellsph/io/number_format.hpp"

namespace cellsph {

namespace io::detail {

// Dimension of a particle type, from its position vector.
template <class P>
inline constexpr int particle_dim = std::remove_cvref_t<decltype(std::declval<const P&>().x[0])>::dim;

// Fields that have their fixed place at the front of the row.
inline bool leading_field(std::string_view name) {
  return name == "position" || name == "velocity" || name == "density" || name == "pressure" ||
         name == "phase";
}

template <class Vector>
void append_value(std::string& line, const Vector& field, std::size_t i) {
  using FT = io::FieldOf<Vector>;
  for (int k = 0; k < FT::components; ++k) {
    line += ',';
    io::append_number(line, FT::get(field[i], k));
  }
}

template <class P>
void append_row(std::string& out, const P& p, std::size_t i) {
  constexpr int Dim = particle_dim<P>;
  for (int k = 0; k < Dim; ++k) {
    if (k) out += ',';
    io::append_number(out, p.x[i][k]);
  }
  for (int k = 0; k < Dim; ++k) {
    out += ',';
    io::append_number(out, p.v[i][k]);
  }
  out += ',';
  io::append_number(out, p.rho[i]);
  out += ',';
  io::append_number(out, p.p[i]);
  out += ',';
  io::append_number(out, p.phase[i]);
  p.for_each_field([&](std::string_view name, const auto& field) {
    if (!leading_field(name)) append_value(out, field, i);
  });
  out += '\n';
}

}  // namespace io::detail

// Generic over the particle type (x, v, rho, p, phase, size(), for_each_field()); csv_header() and
// write_csv() instantiate them for Particles, tests for an extended field list.
template <class P>
std::string csv_header_any() {
  using namespace io::detail;
  constexpr int Dim = particle_dim<P>;
  static constexpr const char* axes[3] = {"x", "y", "z"};
  std::string h;
  // Appends only: GCC 12 flags operator+ chains on strings with a false -Wrestrict.
  for (int k = 0; k < Dim; ++k) {
    if (k) h += ',';
    h += axes[k];
  }
  for (int k = 0; k < Dim; ++k) {
    h += ",v";
    h += axes[k];
  }
  h += ",density,pressure,phase";
  P none;
  none.for_each_field([&](std::string_view name, const auto& field) {
    if (leading_field(name)) return;
    using FT = io::FieldOf<decltype(field)>;
    if constexpr (FT::is_vector) {
      for (int k = 0; k < FT::components; ++k) {
        h += ',';
        h += name;
        h += '_';
        h += axes[k];
      }
    } else {
      static_assert(FT::components == 1);
      h += ',';
      h += name;
    }
  });
  return h;
}

template <class P>
void write_csv_any(const P& particles, const std::filesystem::path& path, const CsvRowFilter& keep) {
  using namespace io::detail;
  io::check_field_sizes(particles);
  AtomicFile file(path, true);
  auto& out = file.stream();
  const std::string header = csv_header_any<P>() + "\n";
  out.write(header.data(), static_cast<std::streamsize>(header.size()));

  // Format a batch of chunks in parallel, then write them in order; memory stays bounded.
  const std::size_t n = particles.size();
  constexpr std::size_t chunk = 8192;
  const std::size_t per_batch = 4 * static_cast<std::size_t>(std::max(1, max_threads()));
  std::vector<std::string> texts(per_batch);
  for (std::size_t b0 = 0; b0 < n; b0 += per_batch * chunk) {
    const std::size_t nchunks = std::min(per_batch, (n - b0 + chunk - 1) / chunk);
    parallel_for(nchunks, [&](std::size_t c) {
      std::string& s = texts[c];
      s.clear();
      const std::size_t i0 = b0 + c * chunk;
      const std::size_t i1 = std::min(n, i0 + chunk);
      for (std::size_t i = i0; i < i1; ++i)
        if (!keep || keep(i)) append_row(s, particles, i);
    });
    for (std::size_t c = 0; c < nchunks; ++c)
      out.write(texts[c].data(), static_cast<std::streamsize>(texts[c].size()));
  }
  file.commit();
}

}  // namespace cellsph
