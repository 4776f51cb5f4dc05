#include "cellsph/io/vtu_writer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

// An independent reader of what ParaView needs from the file: the DataArray tags of the XML header
// and the raw appended blocks (UInt64 byte count, then the values).
struct ArrayTag {
  std::string section;  // FieldData, PointData, Points or Cells
  std::string type;
  int components = 0;
  std::uint64_t offset = 0;
  std::uint64_t tuples = 0;
};

std::string attr(const std::string& tag, const std::string& key) {
  const auto a = tag.find(" " + key + "=\"");
  if (a == std::string::npos) return "";
  const auto b = a + key.size() + 3;
  return tag.substr(b, tag.find('"', b) - b);
}

struct ParsedVtu {
  std::string header;
  std::map<std::string, ArrayTag> arrays;
  std::string bytes;
  std::size_t data_start = 0;  // first byte after '_'
  std::size_t data_end = 0;    // where "\n  </AppendedData>" begins

  template <class T>
  std::vector<T> block(const std::string& name, std::uint64_t* byte_count = nullptr) const {
    const auto& a = arrays.at(name);
    std::uint64_t n;
    std::memcpy(&n, bytes.data() + data_start + a.offset, 8);
    if (byte_count) *byte_count = n;
    std::vector<T> v(n / sizeof(T));
    if (n) std::memcpy(v.data(), bytes.data() + data_start + a.offset + 8, n);
    return v;
  }
};

ParsedVtu parse_vtu(const std::filesystem::path& path) {
  ParsedVtu r;
  r.bytes = test::slurp(path);
  const auto app = r.bytes.find("<AppendedData encoding=\"raw\">");
  EXPECT_NE(app, std::string::npos);
  r.header = r.bytes.substr(0, app);
  r.data_start = r.bytes.find('_', app) + 1;
  r.data_end = r.bytes.rfind("\n  </AppendedData>");
  std::string section;
  for (std::size_t p = 0; (p = r.header.find('<', p)) != std::string::npos; ++p) {
    const auto e = r.header.find('>', p);
    const std::string tag = r.header.substr(p, e - p + 1);
    for (const char* s : {"FieldData", "PointData", "Points", "Cells"})
      if (tag.rfind(std::string("<") + s + ">", 0) == 0) section = s;
    if (tag.rfind("<DataArray", 0) == 0) {
      EXPECT_EQ(attr(tag, "format"), "appended") << tag;
      ArrayTag a{section, attr(tag, "type"), std::stoi(attr(tag, "NumberOfComponents")),
                 std::stoull(attr(tag, "offset")), std::stoull(attr(tag, "NumberOfTuples"))};
      EXPECT_TRUE(r.arrays.emplace(attr(tag, "Name"), a).second) << "duplicate array " << tag;
    }
  }
  return r;
}

template <class T>
void expect_same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(T)), 0);
}

template <int Dim, class Real>
void check_vtu_round_trip() {
  test::TempDir dir("vtu");
  const std::size_t n = 37;
  const auto p = test::make_particles<Dim, Real>(n);
  const auto file = dir / "frame.vtu";
  write_vtu(p, 1.25, file);
  const ParsedVtu v = parse_vtu(file);

  EXPECT_NE(v.header.find("type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(v.header.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(v.header.find("byte_order=\"LittleEndian\""), std::string::npos);
  EXPECT_NE(v.header.find("NumberOfPoints=\"37\" NumberOfCells=\"37\""), std::string::npos);

  const std::string real = sizeof(Real) == 4 ? "Float32" : "Float64";
  // Every field of the list, written out here by hand, with its VTK type and width.
  const std::map<std::string, std::pair<std::string, int>> expected = {
      {"velocity", {real, 3}}, {"force", {real, 3}},   {"mass", {real, 1}},  {"density", {real, 1}},
      {"pressure", {real, 1}}, {"support", {real, 1}}, {"color", {real, 1}}, {"viscosity", {real, 1}},
      {"phase", {"Int32", 1}}, {"level", {"Int32", 1}}};
  for (const auto& [name, tc] : expected) {
    ASSERT_TRUE(v.arrays.count(name)) << name;
    EXPECT_EQ(v.arrays.at(name).section, "PointData") << name;
    EXPECT_EQ(v.arrays.at(name).type, tc.first) << name;
    EXPECT_EQ(v.arrays.at(name).components, tc.second) << name;
  }
  EXPECT_EQ(v.arrays.at("position").section, "Points");
  EXPECT_EQ(v.arrays.at("position").components, 3);
  EXPECT_EQ(v.arrays.at("TimeValue").section, "FieldData");
  EXPECT_EQ(v.block<double>("TimeValue"), std::vector<double>{1.25});
  // VTK reads FieldData arrays only as far as their NumberOfTuples says.
  EXPECT_EQ(v.arrays.at("TimeValue").tuples, 1u);
  for (const auto& [name, a] : v.arrays) {
    if (name != "TimeValue") {
      EXPECT_EQ(a.tuples, n) << name;
    }
  }

  // Blocks tile the appended section exactly, in offset order, each sized by its header.
  std::vector<std::pair<std::uint64_t, std::string>> order;
  for (const auto& [name, a] : v.arrays) order.emplace_back(a.offset, name);
  std::sort(order.begin(), order.end());
  std::uint64_t at = 0;
  for (const auto& [off, name] : order) {
    EXPECT_EQ(off, at) << name;
    std::uint64_t count;
    std::memcpy(&count, v.bytes.data() + v.data_start + off, 8);
    at = off + 8 + count;
  }
  EXPECT_EQ(v.data_start + at, v.data_end);

  // Values, bit for bit, vectors padded with z = 0.
  auto padded = [&](const std::vector<Vec<Dim, Real>>& f) {
    std::vector<Real> r;
    for (const auto& x : f)
      for (int k = 0; k < 3; ++k) r.push_back(k < Dim ? x[k] : Real(0));
    return r;
  };
  std::uint64_t bytes = 0;
  expect_same_bits(v.block<Real>("position", &bytes), padded(p.x));
  EXPECT_EQ(bytes, n * 3 * sizeof(Real));
  expect_same_bits(v.block<Real>("velocity"), padded(p.v));
  expect_same_bits(v.block<Real>("force"), padded(p.f));
  expect_same_bits(v.block<Real>("mass"), p.m);
  expect_same_bits(v.block<Real>("density"), p.rho);
  expect_same_bits(v.block<Real>("pressure"), p.p);
  expect_same_bits(v.block<Real>("support"), p.h);
  expect_same_bits(v.block<Real>("color"), p.color);
  expect_same_bits(v.block<Real>("viscosity"), p.mu);
  expect_same_bits(v.block<std::int32_t>("phase"), p.phase);
  expect_same_bits(v.block<std::int32_t>("level"), p.level);

  // One vertex cell (VTK type 1) per particle.
  EXPECT_EQ(v.arrays.at("connectivity").type, "Int64");
  const auto conn = v.block<std::int64_t>("connectivity");
  const auto offs = v.block<std::int64_t>("offsets");
  const auto types = v.block<std::uint8_t>("types");
  ASSERT_EQ(conn.size(), n);
  ASSERT_EQ(offs.size(), n);
  ASSERT_EQ(types.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(conn[i], static_cast<std::int64_t>(i));
    EXPECT_EQ(offs[i], static_cast<std::int64_t>(i + 1));
    EXPECT_EQ(types[i], 1);
  }
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"frame.vtu"});
}

TEST(VtuWriter, RoundTrip2DFloat) {
  check_vtu_round_trip<2, float>();
}
TEST(VtuWriter, RoundTrip3DDouble) {
  check_vtu_round_trip<3, double>();
}
TEST(VtuWriter, RoundTrip3DFloat) {
  check_vtu_round_trip<3, float>();
}

TEST(VtuWriter, EmptyParticleSetIsValid) {
  test::TempDir dir("vtu_empty");
  write_vtu(Particles<2, double>{}, 0.0, dir / "e.vtu");
  const ParsedVtu v = parse_vtu(dir / "e.vtu");
  EXPECT_NE(v.header.find("NumberOfPoints=\"0\""), std::string::npos);
  EXPECT_TRUE(v.block<double>("density").empty());
}

TEST(VtuWriter, ReplacesTargetAndLeavesNoTemporaryFile) {
  test::TempDir dir("vtu_atomic");
  test::spit(dir / "f.vtu", "old contents");
  write_vtu(test::make_particles<2, float>(3), 0.5, dir / "f.vtu");
  EXPECT_EQ(test::slurp(dir / "f.vtu").rfind("<?xml", 0), 0u);
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"f.vtu"});
}

TEST(VtuWriter, UnwritableFolderIsAWriteError) {
  test::TempDir dir("vtu_bad");
  EXPECT_THROW(write_vtu(test::make_particles<2, float>(3), 0.5, dir / "missing" / "f.vtu"), WriteError);
  EXPECT_TRUE(dir.listing().empty());
}

TEST(VtuWriter, InconsistentFieldLengthsAreRefusedBeforeWriting) {
  test::TempDir dir("vtu_sizes");
  auto p = test::make_particles<3, double>(4);
  p.level.pop_back();
  EXPECT_THROW(write_vtu(p, 0.0, dir / "f.vtu"), std::logic_error);
  EXPECT_TRUE(dir.listing().empty());
}

// The real consumer: VTK's own XML reader (ParaView's), through Debian's python3-vtk9 when installed.
TEST(VtuWriter, ReadBackByVtkWhenInstalled) {
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-vtk9 is not installed; the independent parser above still checks the format";
  test::TempDir dir("vtu_vtk");
  const auto p = test::make_particles<2, float>(6);
  write_vtu(p, 0.75, dir / "f.vtu");
  test::spit(dir / "read.py",
             "import sys, vtk\n"
             "r = vtk.vtkXMLUnstructuredGridReader()\n"
             "r.SetFileName(sys.argv[1])\n"
             "r.Update()\n"
             "g = r.GetOutput()\n"
             "pd = g.GetPointData()\n"
             "print(g.GetNumberOfPoints(), g.GetNumberOfCells(), g.GetCellType(0))\n"
             "print(g.GetFieldData().GetArray('TimeValue').GetValue(0))\n"
             "print(repr(g.GetPoint(4)))\n"
             "print(pd.GetArray('density').GetValue(4), pd.GetArray('phase').GetValue(4), "
             "pd.GetArray('velocity').GetNumberOfComponents())\n");
  const auto out = dir / "out.txt";
  const std::string cmd = "/usr/bin/python3 " + (dir / "read.py").string() + " " + (dir / "f.vtu").string() +
                          " > " + out.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << test::slurp(out);
  std::istringstream lines(test::slurp(out));
  std::string l1, l2, l3, l4;
  std::getline(lines, l1);
  std::getline(lines, l2);
  std::getline(lines, l3);
  std::getline(lines, l4);
  EXPECT_EQ(l1, "6 6 1");  // points, cells, VTK_VERTEX
  EXPECT_EQ(l2, "0.75");
  // Python prints the float32 values widened to double, shortest repr.
  auto widened = [](float v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.17g", static_cast<double>(v));
    return std::stod(buf);
  };
  double x, y, z;
  ASSERT_EQ(std::sscanf(l3.c_str(), "(%lf, %lf, %lf)", &x, &y, &z), 3) << l3;
  EXPECT_EQ(x, widened(p.x[4][0]));
  EXPECT_EQ(y, widened(p.x[4][1]));
  EXPECT_EQ(z, 0.0);
  double rho;
  int phase, comps;
  ASSERT_EQ(std::sscanf(l4.c_str(), "%lf %d %d", &rho, &phase, &comps), 3) << l4;
  EXPECT_EQ(rho, widened(p.rho[4]));
  EXPECT_EQ(phase, p.phase[4]);
  EXPECT_EQ(comps, 3);
}

// A frame in three pieces (one empty, as a rank may hold no particle) opens through its .pvtu in VTK's own
// reader as the whole set: every point, in piece order, with its values.
TEST(PvtuWriter, PiecesReadBackByVtkAsTheWholeSet) {
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-vtk9 is not installed (scripts/setup.sh --test installs it)";
  test::TempDir dir("pvtu_vtk");
  const auto whole = test::make_particles<3, double>(7);
  std::vector<std::string> names;
  const std::size_t cuts[] = {0, 4, 4, 7};
  for (int k = 0; k < 3; ++k) {
    Particles<3, double> piece;
    piece.resize(cuts[k + 1] - cuts[k]);
    piece.for_each_field([&](std::string_view name, auto& field) {
      whole.for_each_field([&](std::string_view n2, const auto& f2) {
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::decay_t<decltype(f2)>>) {
          if (name == n2)
            std::copy(f2.begin() + long(cuts[k]), f2.begin() + long(cuts[k + 1]), field.begin());
        }
      });
    });
    names.push_back("f_" + std::to_string(k) + ".vtu");
    write_vtu(piece, 0.5, dir / names.back());
  }
  write_pvtu(whole, names, dir / "f.pvtu");
  test::spit(dir / "read.py",
             "import sys, vtk\n"
             "r = vtk.vtkXMLPUnstructuredGridReader()\n"
             "r.SetFileName(sys.argv[1])\n"
             "r.Update()\n"
             "g = r.GetOutput()\n"
             "pd = g.GetPointData()\n"
             "print(g.GetNumberOfPoints(), pd.GetNumberOfArrays())\n"
             "for i in range(g.GetNumberOfPoints()):\n"
             "    print(repr(g.GetPoint(i)[0]), repr(pd.GetArray('density').GetValue(i)), "
             "pd.GetArray('id').GetValue(i))\n");
  const auto out = dir / "out.txt";
  const std::string cmd = "/usr/bin/python3 " + (dir / "read.py").string() + " " + (dir / "f.pvtu").string() +
                          " > " + out.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << test::slurp(out);
  std::istringstream lines(test::slurp(out));
  std::size_t points = 0, arrays = 0;
  lines >> points >> arrays;
  EXPECT_EQ(points, whole.size());
  std::size_t fields = 0;
  whole.for_each_field([&](std::string_view, const auto&) { ++fields; });
  EXPECT_EQ(arrays, fields - 1);  // position is the Points
  for (std::size_t i = 0; i < whole.size(); ++i) {
    double x = 0, rho = 0;
    long long id = -1;
    lines >> x >> rho >> id;
    EXPECT_EQ(x, whole.x[i][0]) << "point " << i;
    EXPECT_EQ(rho, whole.rho[i]) << "point " << i;
    EXPECT_EQ(id, static_cast<long long>(whole.id[i])) << "point " << i;
  }
}

TEST(PvdWriter, ListsEveryFrameWithItsTimeAfterEachAdd) {
  test::TempDir dir("pvd");
  PvdWriter pvd(dir / "run.pvd");
  pvd.add(0.0, "frame_00000.vtu");
  const std::string one = test::slurp(dir / "run.pvd");
  EXPECT_NE(one.find("<DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"frame_00000.vtu\"/>"),
            std::string::npos);
  EXPECT_EQ(one.find("frame_00001"), std::string::npos);
  pvd.add(0.1, "frame_00001.vtu");
  const std::string two = test::slurp(dir / "run.pvd");
  EXPECT_NE(two.find("type=\"Collection\""), std::string::npos);
  EXPECT_NE(two.find("<DataSet timestep=\"0.1\" group=\"\" part=\"0\" file=\"frame_00001.vtu\"/>"),
            std::string::npos);
  EXPECT_NE(two.rfind("</VTKFile>\n"), std::string::npos);
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"run.pvd"});

  const auto back = read_pvd(dir / "run.pvd");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].time, 0.1);
  EXPECT_EQ(back[1].file, "frame_00001.vtu");
}

TEST(PvdWriter, ReadRejectsOtherFiles) {
  test::TempDir dir("pvd_bad");
  test::spit(dir / "x.pvd", "<VTKFile type=\"UnstructuredGrid\"></VTKFile>");
  try {
    read_pvd(dir / "x.pvd");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.pvd"), std::string::npos);
  }
}

}  // namespace
}  // namespace cellsph
