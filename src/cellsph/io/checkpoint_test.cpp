#include "cellsph/io/checkpoint.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <limits>

#include "cellsph/core/error.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

template <int Dim, class Real>
void check_round_trip() {
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
  check_round_trip<2, float>();
}
TEST(Checkpoint, RoundTripIsBitExact3DDouble) {
  check_round_trip<3, double>();
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

  // Drop the last field ("id": 4-byte name length, name, size, count, data) and lower the count.
  const auto lvl = good_.rfind(std::string("\x02\0\0\0id", 6));
  const auto missing = with([&](std::string& b) {
    const std::size_t nfields_at = 8 + 4 * 4 + 8 * 3 + 8 + 5;  // header, user blob "state"
    b[nfields_at] = static_cast<char>(b[nfields_at] - 1);
    b.erase(lvl, b.size() - 8 - lvl);
  });
  EXPECT_NE(missing.find("missing field 'id'"), std::string::npos) << missing;

  const auto dup = with([&](std::string& b) { b.replace(b.rfind("level"), 5, "phase"); });
  EXPECT_NE(dup.find("field 'phase' appears twice"), std::string::npos) << dup;
}

TEST_F(CheckpointErrors, MissingFileIsNamed) {
  EXPECT_NE(load_error(dir_ / "nope.ckpt").find("cannot read"), std::string::npos);
}

}  // namespace
}  // namespace cellsph
