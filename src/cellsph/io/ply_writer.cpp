#include "cellsph/io/ply_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/io/field_types.hpp"
#include "cellsph/io/number_format.hpp"

namespace cellsph {

static_assert(std::endian::native == std::endian::little, "the PLY writer declares binary_little_endian");

template <int Dim, class Real>
void write_ply(const Particles<Dim, Real>& particles, double time, const std::filesystem::path& path) {
  io::check_field_sizes(particles);
  const std::size_t n = particles.size();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by cellsph\ncomment time ";
  io::append_number(header, time);
  header += "\nelement vertex " + std::to_string(n) + "\n";
  for (const char* name : {"x", "y", "z", "vx", "vy", "vz", "density", "pressure"})
    header += std::string("property float ") + name + "\n";
  header += "property int phase\nend_header\n";

  AtomicFile file(path, true);
  auto& out = file.stream();
  out.write(header.data(), static_cast<std::streamsize>(header.size()));

  constexpr std::size_t record = 8 * sizeof(float) + sizeof(std::int32_t);
  constexpr std::size_t chunk = 8192;
  std::vector<char> buf(chunk * record);
  for (std::size_t i0 = 0; i0 < n; i0 += chunk) {
    const std::size_t i1 = std::min(n, i0 + chunk);
    char* w = buf.data();
    for (std::size_t i = i0; i < i1; ++i) {
      float rec[8] = {};
      for (int k = 0; k < Dim; ++k) {
        rec[k] = static_cast<float>(particles.x[i][k]);
        rec[3 + k] = static_cast<float>(particles.v[i][k]);
      }
      rec[6] = static_cast<float>(particles.rho[i]);
      rec[7] = static_cast<float>(particles.p[i]);
      std::memcpy(w, rec, sizeof(rec));
      std::memcpy(w + sizeof(rec), &particles.phase[i], sizeof(std::int32_t));
      w += record;
    }
    out.write(buf.data(), static_cast<std::streamsize>(w - buf.data()));
  }
  file.commit();
}

template void write_ply<2, float>(const Particles<2, float>&, double, const std::filesystem::path&);
template void write_ply<2, double>(const Particles<2, double>&, double, const std::filesystem::path&);
template void write_ply<3, float>(const Particles<3, float>&, double, const std::filesystem::path&);
template void write_ply<3, double>(const Particles<3, double>&, double, const std::filesystem::path&);

}  // namespace cellsph
