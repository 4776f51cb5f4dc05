// The points CSV reader on its own (the command-line tests in app/cli_neighbors_test.cpp cover
// the same errors through the program).
#include "cellsph/io/points_csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "cellsph/core/error.hpp"

namespace cellsph {
namespace {

// The InputError message of parsing `text`, or "" when it parses.
std::string error_of(const std::string& text) {
  try {
    parse_points_csv(text, "f.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PointsCsv, ReadsEveryDoubleExactly) {
  // Values printed with 17 significant digits must read back bit for bit (std::from_chars rounds
  // correctly), including negative, tiny, huge and integral ones.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  std::vector<double> values = {0.0, -0.0, 1.0, -2.5, 1e-300, 4.9e-310, 1.7976931348623157e308, 123456789.0};
  for (int i = 0; i < 1000; ++i) values.push_back(u(rng) * std::pow(10.0, double(i % 40 - 20)));
  std::string text = "z,x,y\n";
  for (std::size_t i = 0; i < values.size(); ++i) {
    char row[128];
    std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g\n", values[i], -values[i],
                  values[(i + 1) % values.size()]);
    text += row;
  }
  const PointsTable t = parse_points_csv(text, "f.csv");
  ASSERT_EQ(t.dim, 3);
  ASSERT_EQ(t.size(), values.size());
  EXPECT_FALSE(t.has_h());
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(t.coord[2][i], values[i]);  // column z came first in the file
    EXPECT_EQ(t.coord[0][i], -values[i]);
    EXPECT_EQ(t.coord[1][i], values[(i + 1) % values.size()]);
  }
  const auto x = t.points<3, float>();
  ASSERT_EQ(x.size(), values.size());
  const float z3 = x[3][2];
  EXPECT_TRUE(z3 == static_cast<float>(values[3]));
}

TEST(PointsCsv, TwoDimensionsWithSupportAndExtraColumns) {
  const PointsTable t = parse_points_csv(
      "\xEF\xBB\xBFname,h,y,x,extra\r\n a , 0.5 , 2 , 1 ,\r\nb,1e-3,-4,3,zz\r\n\r\n", "f.csv");
  EXPECT_EQ(t.dim, 2);
  ASSERT_EQ(t.size(), 2u);
  ASSERT_TRUE(t.has_h());
  EXPECT_EQ(t.h[0], 0.5);
  EXPECT_EQ(t.h[1], 1e-3);
  EXPECT_EQ(t.coord[0][1], 3.0);
  EXPECT_EQ(t.coord[1][1], -4.0);
}

TEST(PointsCsv, ErrorsNameFileLineColumnAndValue) {
  EXPECT_EQ(error_of("x,y\n1,2\n3,4e\n"),
            "points file 'f.csv', line 3, column 'y' (column 2): not a number: '4e'");
  EXPECT_EQ(error_of("y,x\n1,2\n- 3,4\n"),
            "points file 'f.csv', line 3, column 'y' (column 1): not a number: '- 3'");
  EXPECT_EQ(error_of("x,y\n1,inf\n"),
            "points file 'f.csv', line 2, column 'y' (column 2): not a finite number: 'inf'");
  EXPECT_EQ(error_of("x,y,h\n1,2,-1\n"),
            "points file 'f.csv', line 2, column 'h' (column 3): support length h must be > 0: '-1'");
  EXPECT_EQ(error_of("x,y\n1,2,\n"),
            "points file 'f.csv', line 2: row has 3 field(s), the header has 2: '1,2,'");
  EXPECT_EQ(
      error_of("a,y\n1,2\n"),
      "points file 'f.csv', line 1: missing column 'x' (header: 'a,y'; expected x,y or x,y,z, optionally h)");
  EXPECT_EQ(error_of(""), "points file 'f.csv' is empty (expected a header row naming columns x,y or x,y,z)");
  EXPECT_EQ(error_of("x,y\r\n"), "points file 'f.csv' has a header but no data rows");
  EXPECT_EQ(error_of("\nx,y\n1,2\n"),
            "points file 'f.csv', line 1: expected the header row (x,y or x,y,z), found an empty line");
  // Control characters are shown escaped, long values cut short: the message stays one line.
  EXPECT_EQ(error_of("x,y\n1,\x01\n"),
            "points file 'f.csv', line 2, column 'y' (column 2): not a number: '\\x01'");
  const std::string msg = error_of("x,y\n1," + std::string(100, '7') + "q\n");
  EXPECT_NE(msg.find("'7777777777777777777777777777777777777777...'"), std::string::npos) << msg;
}

TEST(PointsCsv, UnreadableFile) {
  try {
    read_points_csv("/nonexistent/dir/points.csv");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot read points file '/nonexistent/dir/points.csv': No such file or directory");
  }
}

}  // namespace
}  // namespace cellsph
