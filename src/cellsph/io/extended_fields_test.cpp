// The writers are generated from the field list: a particle type with more fields (of new element
// types) is written, read back and validated without any change to the writers.
#include <gtest/gtest.h>

#include <cstring>

#include "cellsph/core/error.hpp"
#include "cellsph/io/checkpoint_impl.hpp"
#include "cellsph/io/csv_writer_impl.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/io/vtu_writer_impl.hpp"

namespace cellsph {
namespace {

template <int Dim, class Real>
struct ExtendedParticles : Particles<Dim, Real> {
  std::vector<std::uint8_t> flag;
  std::vector<std::int64_t> serial;
  std::vector<Vec<Dim, Real>> normal;

  template <class Self, class F>
  static void for_each_field(Self& self, F&& fn) {
    Particles<Dim, Real>::for_each_field(self, fn);
    fn(std::string_view("flag"), self.flag);
    fn(std::string_view("serial"), self.serial);
    fn(std::string_view("normal"), self.normal);
  }
  template <class F>
  void for_each_field(F&& fn) {
    for_each_field(*this, fn);
  }
  template <class F>
  void for_each_field(F&& fn) const {
    for_each_field(*this, fn);
  }
  void resize(std::size_t n) {
    for_each_field([n](std::string_view, auto& field) { field.resize(n); });
  }
};

ExtendedParticles<2, float> make_extended(std::size_t n) {
  ExtendedParticles<2, float> e;
  static_cast<Particles<2, float>&>(e) = test::make_particles<2, float>(n);
  e.flag.resize(n);
  e.serial.resize(n);
  e.normal.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    e.flag[i] = static_cast<std::uint8_t>(200 + i);
    e.serial[i] = (std::int64_t{1} << 40) + static_cast<std::int64_t>(i);
    e.normal[i] = Vec<2, float>{{0.6f, -0.8f * static_cast<float>(i)}};
  }
  return e;
}

TEST(ExtendedFields, VtuHasTheNewArraysWithTheirTypes) {
  test::TempDir dir("ext_vtu");
  const auto e = make_extended(5);
  write_vtu_any(e, 0.0, dir / "e.vtu");
  const std::string text = test::slurp(dir / "e.vtu");
  EXPECT_NE(text.find("type=\"UInt8\" Name=\"flag\" NumberOfComponents=\"1\""), std::string::npos);
  EXPECT_NE(text.find("type=\"Int64\" Name=\"serial\" NumberOfComponents=\"1\""), std::string::npos);
  EXPECT_NE(text.find("type=\"Float32\" Name=\"normal\" NumberOfComponents=\"3\""), std::string::npos);
  // The id block: its offset from the header, then count and values.
  const auto tag = text.find("Name=\"serial\"");
  const auto off_at = text.find("offset=\"", tag) + 8;
  const auto offset = std::stoull(text.substr(off_at, text.find('"', off_at) - off_at));
  const auto data = text.find('_', text.find("<AppendedData")) + 1;
  std::uint64_t bytes;
  std::memcpy(&bytes, text.data() + data + offset, 8);
  ASSERT_EQ(bytes, 5 * sizeof(std::int64_t));
  std::int64_t id3;
  std::memcpy(&id3, text.data() + data + offset + 8 + 3 * 8, 8);
  EXPECT_EQ(id3, (std::int64_t{1} << 40) + 3);
}

TEST(ExtendedFields, CsvAppendsTheNewColumns) {
  test::TempDir dir("ext_csv");
  const auto e = make_extended(3);
  EXPECT_EQ((csv_header_any<ExtendedParticles<2, float>>()),
            "x,y,vx,vy,density,pressure,phase,force_x,force_y,mass,support,color,viscosity,level,tick,kind,"
            "id,flag,serial,"
            "normal_x,normal_y");
  write_csv_any(e, dir / "e.csv", {});
  const std::string text = test::slurp(dir / "e.csv");
  const auto row2 = text.find('\n', text.find('\n', text.find('\n') + 1) + 1) + 1;  // third data row
  const std::string line = text.substr(row2, text.find('\n', row2) - row2);
  EXPECT_NE(line.find(",202,1099511627778,0.6,-1.6"), std::string::npos) << line;
}

TEST(ExtendedFields, CheckpointRoundTripAndFieldListMismatch) {
  test::TempDir dir("ext_ckpt");
  const auto e = make_extended(7);
  write_checkpoint_any(e, {2.0, 3, "x"}, dir / "e.ckpt");
  ExtendedParticles<2, float> back;
  read_checkpoint_any(dir / "e.ckpt", back);
  EXPECT_EQ(back.flag, e.flag);
  EXPECT_EQ(back.serial, e.serial);
  EXPECT_EQ(back.normal, e.normal);
  EXPECT_EQ(back.x, e.x);

  // A build without these fields refuses the file, and the other way round.
  Particles<2, float> plain;
  try {
    read_checkpoint_any(dir / "e.ckpt", plain);
    FAIL() << "no error";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("unknown field 'flag'"), std::string::npos) << err.what();
  }
  write_checkpoint_any(test::make_particles<2, float>(4), {}, dir / "p.ckpt");
  try {
    read_checkpoint_any(dir / "p.ckpt", back);
    FAIL() << "no error";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("missing field"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace cellsph
