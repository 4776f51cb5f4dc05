#include "cellsph/io/csv_writer.hpp"

#include "cellsph/io/csv_writer_impl.hpp"

namespace cellsph {

template <int Dim, class Real>
std::string csv_header() {
  return csv_header_any<Particles<Dim, Real>>();
}

template <int Dim, class Real>
void write_csv(const Particles<Dim, Real>& particles, const std::filesystem::path& path,
               const CsvRowFilter& keep) {
  write_csv_any(particles, path, keep);
}

#define CELLSPH_CSV_INSTANTIATE(D, R)      \
  template std::string csv_header<D, R>(); \
  template void write_csv<D, R>(const Particles<D, R>&, const std::filesystem::path&, const CsvRowFilter&);
CELLSPH_CSV_INSTANTIATE(2, float)
CELLSPH_CSV_INSTANTIATE(2, double)
CELLSPH_CSV_INSTANTIATE(3, float)
CELLSPH_CSV_INSTANTIATE(3, double)
#undef CELLSPH_CSV_INSTANTIATE

}  // namespace cellsph
