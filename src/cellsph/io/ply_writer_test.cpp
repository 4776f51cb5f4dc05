#include "cellsph/io/ply_writer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

template <int Dim, class Real>
void check_ply() {
  test::TempDir dir("ply");
  const std::size_t n = 23;
  const auto p = test::make_particles<Dim, Real>(n);
  write_ply(p, 2.5, dir / "f.ply");
  const std::string bytes = test::slurp(dir / "f.ply");

  // Header: text lines up to end_header.
  const std::string end = "end_header\n";
  const auto body = bytes.find(end);
  ASSERT_NE(body, std::string::npos);
  std::istringstream header(bytes.substr(0, body));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(header, line)) lines.push_back(line);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines[0], "ply");
  EXPECT_EQ(lines[1], "format binary_little_endian 1.0");
  std::vector<std::string> props;
  std::size_t count = 0;
  for (const auto& l : lines) {
    if (l.rfind("element vertex ", 0) == 0) count = std::stoul(l.substr(15));
    if (l.rfind("property ", 0) == 0) props.push_back(l.substr(9));
  }
  EXPECT_EQ(count, n);
  EXPECT_EQ(props, (std::vector<std::string>{"float x", "float y", "float z", "float vx", "float vy",
                                             "float vz", "float density", "float pressure", "int phase"}));

  // Body: n records of 8 floats and one int32, nothing after.
  const char* d = bytes.data() + body + end.size();
  ASSERT_EQ(bytes.size() - body - end.size(), n * 36);
  for (std::size_t i = 0; i < n; ++i, d += 36) {
    float r[8];
    std::int32_t phase;
    std::memcpy(r, d, sizeof(r));
    std::memcpy(&phase, d + 32, 4);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(r[k], k < Dim ? static_cast<float>(p.x[i][k]) : 0.0f);
      EXPECT_EQ(r[3 + k], k < Dim ? static_cast<float>(p.v[i][k]) : 0.0f);
    }
    EXPECT_EQ(r[6], static_cast<float>(p.rho[i]));
    EXPECT_EQ(r[7], static_cast<float>(p.p[i]));
    EXPECT_EQ(phase, p.phase[i]);
  }
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"f.ply"});
}

TEST(PlyWriter, Binary2DDouble) {
  check_ply<2, double>();
}
TEST(PlyWriter, Binary3DFloat) {
  check_ply<3, float>();
}

}  // namespace
}  // namespace cellsph
