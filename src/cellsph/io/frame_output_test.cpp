#include "cellsph/io/frame_output.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

TEST(FrameOutput, WritesEveryFormatThenTheIndexes) {
  test::TempDir dir("frames_out");
  const auto p = test::make_particles<2, float>(12);
  FrameOutput<2, float> out(dir.path() / "run", parse_output_formats("ply,vtu,csv"));
  out.write(p, 0, 0.0);
  const auto files = out.write(p, 1, 0.05);
  EXPECT_EQ(files.size(), 3u);
  const test::TempDir& d = dir;
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(d.path() / "run"))
    names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"frame_00000.csv", "frame_00000.ply", "frame_00000.vtu",
                                             "frame_00001.csv", "frame_00001.ply", "frame_00001.vtu",
                                             "frames.csv", "particles.pvd"}));
  EXPECT_EQ(test::slurp(dir.path() / "run" / "frames.csv"),
            "frame,time,vtu,ply,csv\n"
            "0,0,frame_00000.vtu,frame_00000.ply,frame_00000.csv\n"
            "1,0.05,frame_00001.vtu,frame_00001.ply,frame_00001.csv\n");
  const auto pvd = read_pvd(dir.path() / "run" / "particles.pvd");
  ASSERT_EQ(pvd.size(), 2u);
  EXPECT_EQ(pvd[1].file, "frame_00001.vtu");
  EXPECT_EQ(pvd[1].time, 0.05);
}

// The Simulation keeps its particles in cell order; frames are written in id order, with the row filter
// still asked about the caller's indices (cmd_run's "is fluid" reads the simulation's own arrays).
TEST(FrameOutput, WritesParticlesInIdOrder) {
  test::TempDir dir("frames_ids");
  const std::size_t n = 9;
  const auto p = test::make_particles<2, double>(n);  // ids 0..8 in order
  const std::vector<std::uint32_t> perm{4, 7, 0, 8, 2, 5, 1, 6, 3};
  Particles<2, double> q;  // internal order: q[i] is the particle with id perm[i]
  q.resize(n);
  p.for_each_field([&](std::string_view name, const auto& src) {
    q.for_each_field([&](std::string_view qname, auto& dst) {
      if constexpr (std::is_same_v<std::remove_cvref_t<decltype(src)>, std::remove_cvref_t<decltype(dst)>>)
        if (name == qname)
          for (std::size_t i = 0; i < n; ++i) dst[i] = src[perm[i]];
    });
  });
  ASSERT_FALSE(in_id_order(q));
  // Drop the internal indices 1 and 4 (ids 7 and 2).
  FrameOutput<2, double> out(dir.path(), parse_output_formats("csv"),
                             [](std::size_t i) { return i != 1 && i != 4; });
  out.write(q, 0, 0.0);
  std::istringstream in(test::slurp(dir.path() / "frame_00000.csv"));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream hs(line); std::getline(hs, line, ',');) header.push_back(line);
  const auto id_col =
      static_cast<std::size_t>(std::find(header.begin(), header.end(), "id") - header.begin());
  ASSERT_LT(id_col, header.size());
  std::vector<std::uint32_t> ids;
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    for (std::stringstream ls(line); std::getline(ls, line, ',');) c.push_back(line);
    ASSERT_EQ(c.size(), header.size());
    const auto id = static_cast<std::uint32_t>(std::stoul(c[id_col]));
    ids.push_back(id);
    EXPECT_EQ(std::stod(c[0]), p.x[id][0]) << "row of id " << id;  // the row carries that particle's data
    EXPECT_EQ(std::stod(c[2]), p.v[id][0]) << "row of id " << id;
  }
  EXPECT_EQ(ids, (std::vector<std::uint32_t>{0, 1, 3, 4, 5, 6, 8}));
}

TEST(FrameOutput, ResumeKeepsEarlierFramesAndDropsLaterOnes) {
  test::TempDir dir("frames_resume");
  const auto p = test::make_particles<3, double>(5);
  {
    FrameOutput<3, double> out(dir.path(), parse_output_formats("vtu"));
    for (std::size_t f = 0; f < 4; ++f) out.write(p, f, 0.1 * static_cast<double>(f));
  }
  FrameOutput<3, double> again(dir.path(), parse_output_formats("vtu"));
  again.resume(2);
  again.write(p, 2, 0.2);
  const auto idx = read_frames_index(dir / "frames.csv");
  ASSERT_EQ(idx.rows().size(), 3u);
  EXPECT_EQ(idx.rows()[2].frame, 2u);
  const auto pvd = read_pvd(dir / "particles.pvd");
  ASSERT_EQ(pvd.size(), 3u);
  EXPECT_EQ(pvd[2].file, "frame_00002.vtu");

  FrameOutput<3, double> other(dir.path(), parse_output_formats("vtu,csv"));
  EXPECT_THROW(other.resume(2), InputError);
}

}  // namespace
}  // namespace cellsph
