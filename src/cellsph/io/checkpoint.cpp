#include "cellsph/io/checkpoint.hpp"

#include <utility>

#include "cellsph/io/checkpoint_impl.hpp"

namespace cellsph {

CheckpointHeader read_checkpoint_header(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read checkpoint '" + path.string() + "'");
  std::string bytes(64, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  io::detail::Cursor c(path, bytes, static_cast<std::size_t>(in.gcount()));
  return io::detail::parse_header(c);
}

template <int Dim, class Real>
void write_checkpoint(const Particles<Dim, Real>& particles, const SolverState<Dim, Real>& state,
                      const CheckpointInfo& info, const std::filesystem::path& path) {
  const CheckpointFields<const Particles<Dim, Real>&, const SolverState<Dim, Real>&> fields{particles, state};
  write_checkpoint_any(fields, info, path);
}

template <int Dim, class Real>
void write_checkpoint(const Particles<Dim, Real>& particles, const CheckpointInfo& info,
                      const std::filesystem::path& path) {
  SolverState<Dim, Real> zero;
  zero.assign_zero(particles.size());
  write_checkpoint(particles, zero, info, path);
}

template <int Dim, class Real>
CheckpointInfo read_checkpoint(const std::filesystem::path& path, Particles<Dim, Real>& particles,
                               SolverState<Dim, Real>& state) {
  CheckpointFields<Particles<Dim, Real>, SolverState<Dim, Real>> fields;
  const CheckpointInfo info = read_checkpoint_any(path, fields);
  particles = std::move(fields.particles);
  state = std::move(fields.state);
  return info;
}

template <int Dim, class Real>
CheckpointInfo read_checkpoint(const std::filesystem::path& path, Particles<Dim, Real>& particles) {
  SolverState<Dim, Real> state;
  return read_checkpoint(path, particles, state);
}

#define CELLSPH_CHECKPOINT_INSTANTIATE(D, R)                                                    \
  template void write_checkpoint<D, R>(const Particles<D, R>&, const SolverState<D, R>&,        \
                                       const CheckpointInfo&, const std::filesystem::path&);    \
  template void write_checkpoint<D, R>(const Particles<D, R>&, const CheckpointInfo&,           \
                                       const std::filesystem::path&);                           \
  template CheckpointInfo read_checkpoint<D, R>(const std::filesystem::path&, Particles<D, R>&, \
                                                SolverState<D, R>&);                            \
  template CheckpointInfo read_checkpoint<D, R>(const std::filesystem::path&, Particles<D, R>&);
CELLSPH_CHECKPOINT_INSTANTIATE(2, float)
CELLSPH_CHECKPOINT_INSTANTIATE(2, double)
CELLSPH_CHECKPOINT_INSTANTIATE(3, float)
CELLSPH_CHECKPOINT_INSTANTIATE(3, double)
#undef CELLSPH_CHECKPOINT_INSTANTIATE

}  // namespace cellsph
