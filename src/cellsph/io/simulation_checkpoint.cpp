#include "cellsph/io/simulation_checkpoint.hpp"

#include <cstring>
#include <type_traits>
#include <utility>

#include "cellsph/core/error.hpp"
#include "cellsph/io/checkpoint.hpp"

namespace cellsph {
namespace {

constexpr char kBlobMagic[8] = {'C', 'S', 'P', 'H', 'S', 'I', 'M', '1'};

template <class T>
void put(std::string& out, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

// Reads the blob; every failure names the file. The blob is inside the checkpoint's checksummed body, so
// a short or odd blob means a file from another writer, not a torn write.
class BlobReader {
 public:
  BlobReader(const std::filesystem::path& path, std::string_view blob) : path_(path), blob_(blob) {}
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("checkpoint '" + path_.string() + "': integrator state: " + what);
  }
  std::string_view bytes(std::size_t n, const char* what) {
    if (n > blob_.size() - pos_)
      fail(std::string("the user data ends (") + std::to_string(blob_.size()) + " bytes) inside " + what);
    const auto s = blob_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  template <class T>
  T get(const char* what) {
    T v;
    std::memcpy(&v, bytes(sizeof(T), what).data(), sizeof(T));
    return v;
  }
  [[nodiscard]] std::size_t left() const { return blob_.size() - pos_; }

 private:
  const std::filesystem::path& path_;
  std::string_view blob_;
  std::size_t pos_ = 0;
};

}  // namespace

template <int Dim, class Real>
void write_simulation_checkpoint(const Simulation<Dim, Real>& sim, std::string_view extra,
                                 const std::filesystem::path& path) {
  const IntegratorState<Real> st = sim.integrator_state();
  CheckpointInfo info;
  info.time = double(st.time);
  info.step = st.steps;
  info.user.append(kBlobMagic, sizeof kBlobMagic);
  put(info.user, kSimulationBlobVersion);
  put(info.user, double(st.last_dt));
  put(info.user, static_cast<std::uint8_t>(st.leapfrog_started));
  put(info.user, st.next_id);
  put(info.user, static_cast<std::uint32_t>(st.emitter_advance.size()));
  for (const double a : st.emitter_advance) put(info.user, a);
  put(info.user, static_cast<std::uint64_t>(extra.size()));
  info.user.append(extra);
  // Version 2: the floating bodies' states.
  put(info.user, static_cast<std::uint32_t>(sim.body_states().size()));
  for (const RigidBodyState& b : sim.body_states()) put(info.user, b);
  write_checkpoint(sim.particles(), sim.solver_state(), info, path);
}

namespace {

// The blob of `info` (see the header): the integrator state and the caller's bytes.
template <class Real>
std::pair<IntegratorState<Real>, std::string> parse_blob(const std::filesystem::path& path,
                                                         const CheckpointInfo& info,
                                                         std::vector<RigidBodyState>* bodies = nullptr) {
  BlobReader r(path, info.user);
  if (info.user.size() < sizeof kBlobMagic ||
      std::memcmp(info.user.data(), kBlobMagic, sizeof kBlobMagic) != 0)
    r.fail("missing (the file was not written by a simulation)");
  r.bytes(sizeof kBlobMagic, "the magic");
  const auto version = r.get<std::uint32_t>("the version");
  if (version != 1 && version != kSimulationBlobVersion)
    r.fail("version " + std::to_string(version) + " is not supported (this build reads 1 and " +
           std::to_string(kSimulationBlobVersion) + ")");
  IntegratorState<Real> st;
  st.time = static_cast<Real>(info.time);
  st.steps = info.step;
  st.last_dt = static_cast<Real>(r.get<double>("the last time step"));
  const auto started = r.get<std::uint8_t>("the leap-frog flag");
  if (started > 1) r.fail("leap-frog flag " + std::to_string(int(started)) + " is neither 0 nor 1");
  st.leapfrog_started = started != 0;
  if (version >= 2) {
    st.next_id = r.get<std::uint64_t>("the next particle id");
    const auto emitters = r.get<std::uint32_t>("the emitter count");
    if (emitters > r.left() / sizeof(double))
      r.fail(std::to_string(emitters) + " emitters do not fit the " + std::to_string(r.left()) +
             " bytes left");
    for (std::uint32_t e = 0; e < emitters; ++e)
      st.emitter_advance.push_back(r.get<double>("an emitter's advance"));
  }
  const auto n = r.get<std::uint64_t>("the caller data length");
  std::string extra(r.bytes(static_cast<std::size_t>(n), "the caller data"));
  if (version >= 2) {
    const auto count = r.get<std::uint32_t>("the body count");
    if (count > r.left() / sizeof(RigidBodyState))
      r.fail("holds " + std::to_string(count) + " bodies in " + std::to_string(r.left()) + " bytes");
    std::vector<RigidBodyState> states(count);
    for (auto& b : states) b = r.get<RigidBodyState>("a body's state");
    if (bodies) *bodies = std::move(states);
  }
  if (r.left()) r.fail(std::to_string(r.left()) + " unexpected bytes at the end");
  return {st, std::move(extra)};
}

template <int Dim, class Real>
std::string read_extra(const std::filesystem::path& path) {
  Particles<Dim, Real> particles;
  return parse_blob<Real>(path, read_checkpoint(path, particles)).second;
}

}  // namespace

template <int Dim, class Real>
std::string read_simulation_checkpoint(const std::filesystem::path& path, Simulation<Dim, Real>& sim) {
  Particles<Dim, Real> particles;
  SolverState<Dim, Real> solver;
  const CheckpointInfo info = read_checkpoint(path, particles, solver);
  std::vector<RigidBodyState> bodies;
  auto [st, extra] = parse_blob<Real>(path, info, &bodies);
  const std::string source = "checkpoint '" + path.string() + "'";
  // Checked before anything is restored (set_states checks the values again).
  if (bodies.size() != sim.body_states().size())
    throw InputError(source + ": holds the state of " + std::to_string(bodies.size()) +
                     " floating bodies, the scene has " + std::to_string(sim.body_states().size()));
  sim.restore(std::move(particles), st, source, std::move(solver));
  if (!bodies.empty()) sim.restore_bodies(std::move(bodies), source);
  return extra;
}

std::string read_simulation_checkpoint_extra(const std::filesystem::path& path) {
  const CheckpointHeader h = read_checkpoint_header(path);
  const bool f32 = h.real_size == 4;
  if (h.dim == 2) return f32 ? read_extra<2, float>(path) : read_extra<2, double>(path);
  return f32 ? read_extra<3, float>(path) : read_extra<3, double>(path);
}

#define CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE(D, R)                                      \
  template void write_simulation_checkpoint<D, R>(const Simulation<D, R>&, std::string_view, \
                                                  const std::filesystem::path&);             \
  template std::string read_simulation_checkpoint<D, R>(const std::filesystem::path&, Simulation<D, R>&);
CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE(2, float)
CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE(2, double)
CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE(3, float)
CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE(3, double)
#undef CELLSPH_SIMULATION_CHECKPOINT_INSTANTIATE

}  // namespace cellsph
