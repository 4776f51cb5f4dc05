#include "cellsph/io/checkpoint.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/test_paths.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

template <int Dim, class Real>
void check_checkpoint_round_trip() {
  test::TempDir dir("ckpt");
  auto p = test::make_particles<Dim, Real>(101);
  p.v[5][0] = -Real(0);  // sign of zero and a NaN payload must survive too
  p.color[7] = std::numeric_limits<Real>::quiet_NaN();
  const CheckpointInfo info{0.123456789012345, 4711, std::string("leapfrog=1\0bin", 14)};
  write_checkpoint(p, info, dir / "c.ckpt");
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"c.ckpt"});

  const auto h = read_checkpoint_header(dir / "c.ckpt");
  EXPECT_EQ(h.version, kCheckpointVersion);
  EXPECT_EQ(h.dim, Dim);
  EXPECT_EQ(h.real_size, static_cast<int>(sizeof(Real)));
  EXPECT_EQ(h.count, 101u);
  EXPECT_EQ(h.step, 4711u);

  Particles<Dim, Real> q;
  const auto back = read_checkpoint(dir / "c.ckpt", q);
  EXPECT_EQ(back.time, info.time);
  EXPECT_EQ(back.step, info.step);
  EXPECT_EQ(back.user, info.user);
  ASSERT_EQ(q.size(), p.size());
  EXPECT_TRUE(same_bits(q.x, p.x));
  EXPECT_TRUE(same_bits(q.v, p.v));
  EXPECT_TRUE(same_bits(q.f, p.f));
  EXPECT_TRUE(same_bits(q.m, p.m));
  EXPECT_TRUE(same_bits(q.rho, p.rho));
  EXPECT_TRUE(same_bits(q.p, p.p));
  EXPECT_TRUE(same_bits(q.h, p.h));
  EXPECT_TRUE(same_bits(q.color, p.color));
  EXPECT_TRUE(same_bits(q.mu, p.mu));
  EXPECT_TRUE(same_bits(q.phase, p.phase));
  EXPECT_TRUE(same_bits(q.level, p.level));
}

TEST(Checkpoint, RoundTripIsBitExact2DFloat) {
  check_checkpoint_round_trip<2, float>();
}
TEST(Checkpoint, RoundTripIsBitExact3DDouble) {
  check_checkpoint_round_trip<3, double>();
}

// The solver state (solver/particles.hpp) is written after the particle fields and read back bit for bit.
TEST(Checkpoint, SolverStateRoundTrips) {
  test::TempDir dir("ckpt_state");
  const auto p = test::make_particles<2, double>(7);
  SolverState<2, double> state;
  state.dfsph_kappa_v = {1e-9, -0.0, 2.5, 3e300, -4, 5, 6};
  write_checkpoint(p, state, {1.0, 2, ""}, dir / "c.ckpt");
  Particles<2, double> q;
  SolverState<2, double> back;
  read_checkpoint(dir / "c.ckpt", q, back);
  EXPECT_TRUE(same_bits(back.dfsph_kappa_v, state.dfsph_kappa_v));
  EXPECT_TRUE(same_bits(q.x, p.x));
  // Written without a state: 0 for every particle.
  write_checkpoint(p, {1.0, 2, ""}, dir / "z.ckpt");
  read_checkpoint(dir / "z.ckpt", q, back);
  EXPECT_EQ(back.dfsph_kappa_v, std::vector<double>(7, 0.0));
}

// A format-1 file (the checkpoint fuzzer's seed fuzz/corpus/checkpoint/checkpoint-2d.bin, written by a
// build before the solver state existed: 33 particles of a 2D double run at t = 0.03 s, step 3) is still
// read, with a solver state of 0 (what that build resumed with).
TEST(Checkpoint, Version1FileIsReadWithAZeroSolverState) {
  const std::filesystem::path file =
      std::string(cellsph::test::source_dir()) + "/fuzz/corpus/checkpoint/checkpoint-2d.bin";
  const auto h = read_checkpoint_header(file);
  EXPECT_EQ(h.version, 1u);
  Particles<2, double> q;
  SolverState<2, double> state;
  state.dfsph_kappa_v = {1.0};
  const auto info = read_checkpoint(file, q, state);
  EXPECT_EQ(info.step, 3u);
  EXPECT_EQ(info.time, 0.03);
  ASSERT_EQ(q.size(), 33u);
  EXPECT_EQ(state.dfsph_kappa_v, std::vector<double>(33, 0.0));
  std::vector<std::uint32_t> ids(q.id.begin(), q.id.end());
  std::sort(ids.begin(), ids.end());
  for (std::uint32_t k = 0; k < 33; ++k) EXPECT_EQ(ids[k], k);
}

TEST(Checkpoint, EmptyParticleSet) {
  test::TempDir dir("ckpt_empty");
  write_checkpoint(Particles<3, float>{}, {}, dir / "c.ckpt");
  Particles<3, float> q = test::make_particles<3, float>(4);
  read_checkpoint(dir / "c.ckpt", q);
  EXPECT_EQ(q.size(), 0u);
}

// Loads a checkpoint into 3D double particles and returns the error message, checking that it names
// the file and that the target was left untouched.
std::string load_error(const std::filesystem::path& file) {
  auto q = test::make_particles<3, double>(2);
  try {
    read_checkpoint(file, q);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << msg;
    EXPECT_EQ(q.size(), 2u);
    return msg;
  }
  return "no error";
}

class CheckpointErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    write_checkpoint(test::make_particles<3, double>(10), {1.0, 2, "state"}, dir_ / "good.ckpt");
    good_ = test::slurp(dir_ / "good.ckpt");
  }
  // Writes a modified copy and returns the loader's message.
  std::string with(const std::function<void(std::string&)>& edit) {
    std::string bytes = good_;
    edit(bytes);
    test::spit(dir_ / "bad.ckpt", bytes);
    return load_error(dir_ / "bad.ckpt");
  }
  test::TempDir dir_{"ckpt_err"};
  std::string good_;
};

TEST_F(CheckpointErrors, GoodFileLoads) {
  EXPECT_EQ(load_error(dir_ / "good.ckpt"), "no error");
}

TEST_F(CheckpointErrors, BadMagic) {
  EXPECT_NE(with([](std::string& b) { b[0] = 'X'; }).find("bad magic"), std::string::npos);
  EXPECT_NE(with([](std::string& b) { b = "hello"; }).find("bad magic"), std::string::npos);
}

TEST_F(CheckpointErrors, Version) {
  const auto m = with([](std::string& b) { b[8] = 99; });
  EXPECT_NE(m.find("format version 99 is not supported"), std::string::npos) << m;
}

TEST_F(CheckpointErrors, DimensionAndPrecisionMismatch) {
  write_checkpoint(test::make_particles<2, double>(3), {}, dir_ / "two.ckpt");
  EXPECT_NE(load_error(dir_ / "two.ckpt").find("2D run, cannot continue a 3D run"), std::string::npos);
  write_checkpoint(test::make_particles<3, float>(3), {}, dir_ / "float.ckpt");
  const auto m = load_error(dir_ / "float.ckpt");
  EXPECT_NE(m.find("precision mismatch: file holds float"), std::string::npos) << m;
}

TEST_F(CheckpointErrors, TruncatedAnywhere) {
  for (std::size_t keep : {std::size_t{3}, std::size_t{20}, std::size_t{60}, good_.size() / 2,
                           good_.size() - 9, good_.size() - 1}) {
    const auto m = with([&](std::string& b) { b.resize(keep); });
    EXPECT_TRUE(m.find("truncated") != std::string::npos || m.find("bad magic") != std::string::npos ||
                m.find("missing field") != std::string::npos || m.find("checksum") != std::string::npos)
        << keep << ": " << m;
    EXPECT_NE(m, "no error") << keep;
  }
  EXPECT_NE(with([&](std::string& b) { b.resize(b.size() / 2); }).find("truncated"), std::string::npos);
}

TEST_F(CheckpointErrors, CorruptedDataFailsTheChecksum) {
  // Flip one bit inside the position data (after its name, element size and count).
  const auto at = good_.find("position") + 8 + 4 + 8 + 3;
  const auto m = with([at](std::string& b) { b[at] ^= 0x10; });
  EXPECT_NE(m.find("checksum mismatch"), std::string::npos) << m;
}

TEST_F(CheckpointErrors, UnknownAndMissingFields) {
  const auto pos = good_.find("viscosity");
  ASSERT_NE(pos, std::string::npos);
  const auto unknown = with([&](std::string& b) { b.replace(pos, 9, "viscosit2"); });
  EXPECT_NE(unknown.find("unknown field 'viscosit2'"), std::string::npos) << unknown;

  // Drop the last particle field ("id": 4-byte name length, name, size, count, data; the solver state
  // follows) and lower the count.
  const auto lvl = good_.rfind(std::string("\x02\0\0\0id", 6));
  const auto state_at = good_.find(std::string("\x0d\0\0\0dfsph_kappa_v", 17), lvl);
  ASSERT_NE(state_at, std::string::npos);
  const auto missing = with([&](std::string& b) {
    const std::size_t nfields_at = 8 + 4 * 4 + 8 * 3 + 8 + 5;  // header, user blob "state"
    b[nfields_at] = static_cast<char>(b[nfields_at] - 1);
    b.erase(lvl, state_at - lvl);
  });
  EXPECT_NE(missing.find("missing field 'id'"), std::string::npos) << missing;

  // A version-2 file must hold the solver state (only version 1 predates it).
  const auto no_state = with([&](std::string& b) {
    const std::size_t nfields_at = 8 + 4 * 4 + 8 * 3 + 8 + 5;
    b[nfields_at] = static_cast<char>(b[nfields_at] - 1);
    b.erase(state_at, b.size() - 8 - state_at);
  });
  EXPECT_NE(no_state.find("missing field 'dfsph_kappa_v'"), std::string::npos) << no_state;

  const auto dup = with([&](std::string& b) { b.replace(b.rfind("level"), 5, "phase"); });
  EXPECT_NE(dup.find("field 'phase' appears twice"), std::string::npos) << dup;
}

TEST_F(CheckpointErrors, MissingFileIsNamed) {
  EXPECT_NE(load_error(dir_ / "nope.ckpt").find("cannot read"), std::string::npos);
}

}  // namespace
}  // namespace cellsph
