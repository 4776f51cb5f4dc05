#include "cellsph/io/frame_output.hpp"

#include <gtest/gtest.h>

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
