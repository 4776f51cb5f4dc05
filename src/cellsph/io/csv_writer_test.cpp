#include "cellsph/io/csv_writer.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <map>
#include <sstream>

#include "cellsph/core/parallel.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> r;
  std::stringstream ss(s);
  std::string c;
  while (std::getline(ss, c, ',')) r.push_back(c);
  return r;
}

template <class T>
T parse(const std::string& s) {
  T v{};
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  EXPECT_TRUE(r.ec == std::errc() && r.ptr == s.data() + s.size()) << s;
  return v;
}

TEST(CsvWriter, HeaderStartsWithTheContractColumns) {
  EXPECT_EQ(
      (csv_header<2, double>()),
      "x,y,vx,vy,density,pressure,phase,force_x,force_y,mass,support,color,viscosity,level,tick,kind,id");
  EXPECT_EQ((csv_header<3, float>()),
            "x,y,z,vx,vy,vz,density,pressure,phase,force_x,force_y,force_z,mass,support,color,viscosity,"
            "level,tick,kind,id");
}

template <int Dim, class Real>
void check_csv_round_trip() {
  test::TempDir dir("csv");
  const std::size_t n = 20000;  // more than one formatting chunk
  const auto p = test::make_particles<Dim, Real>(n);
  write_csv(p, dir / "f.csv");
  std::istringstream in(test::slurp(dir / "f.csv"));
  std::string line;
  std::getline(in, line);
  const auto head = split(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < head.size(); ++c) col[head[c]] = c;
  const char* axes[] = {"x", "y", "z"};
  std::size_t i = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(i, n);
    const auto c = split(line);
    ASSERT_EQ(c.size(), head.size()) << "row " << i;
    for (int k = 0; k < Dim; ++k) {
      EXPECT_EQ(parse<Real>(c[col[axes[k]]]), p.x[i][k]);
      EXPECT_EQ(parse<Real>(c[col[std::string("v") + axes[k]]]), p.v[i][k]);
      EXPECT_EQ(parse<Real>(c[col[std::string("force_") + axes[k]]]), p.f[i][k]);
    }
    EXPECT_EQ(parse<Real>(c[col["density"]]), p.rho[i]);
    EXPECT_EQ(parse<Real>(c[col["pressure"]]), p.p[i]);
    EXPECT_EQ(parse<std::int32_t>(c[col["phase"]]), p.phase[i]);
    EXPECT_EQ(parse<Real>(c[col["mass"]]), p.m[i]);
    EXPECT_EQ(parse<Real>(c[col["support"]]), p.h[i]);
    EXPECT_EQ(parse<Real>(c[col["color"]]), p.color[i]);
    EXPECT_EQ(parse<Real>(c[col["viscosity"]]), p.mu[i]);
    EXPECT_EQ(parse<std::int32_t>(c[col["level"]]), p.level[i]);
    ++i;
  }
  EXPECT_EQ(i, n);
}

TEST(CsvWriter, RoundTripsBitExactly2DDouble) {
  check_csv_round_trip<2, double>();
}
TEST(CsvWriter, RoundTripsBitExactly3DFloat) {
  check_csv_round_trip<3, float>();
}

TEST(CsvWriter, FilterKeepsOnlySelectedRowsInOrder) {
  test::TempDir dir("csv_filter");
  const auto p = test::make_particles<2, double>(30);
  write_csv(p, dir / "f.csv", [&](std::size_t i) { return p.phase[i] == 1; });
  std::istringstream in(test::slurp(dir / "f.csv"));
  std::string line;
  std::getline(in, line);
  std::vector<double> xs;
  while (std::getline(in, line)) {
    const auto c = split(line);
    EXPECT_EQ(c[6], "1");
    xs.push_back(parse<double>(c[0]));
  }
  std::vector<double> want;
  for (std::size_t i = 1; i < 30; i += 3) want.push_back(p.x[i][0]);
  EXPECT_EQ(xs, want);
}

TEST(CsvWriter, SameBytesForAnyThreadCount) {
  test::TempDir dir("csv_threads");
  const auto p = test::make_particles<3, double>(50000);
  {
    ScopedThreads one(1);
    write_csv(p, dir / "a.csv");
  }
  {
    ScopedThreads two(2);
    write_csv(p, dir / "b.csv");
  }
  EXPECT_EQ(test::slurp(dir / "a.csv"), test::slurp(dir / "b.csv"));
  EXPECT_EQ(dir.listing(), (std::vector<std::string>{"a.csv", "b.csv"}));
}

}  // namespace
}  // namespace cellsph
