#include "cellsph/io/frames_index.hpp"

#include <gtest/gtest.h>

#include <functional>

#include "cellsph/core/error.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(OutputFormats, ParsesAnySubsetIntoCanonicalOrder) {
  const auto f = parse_output_formats("csv,vtu");
  EXPECT_TRUE(f.vtu);
  EXPECT_FALSE(f.ply);
  EXPECT_TRUE(f.csv);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"vtu", "csv"}));
  EXPECT_FALSE(parse_output_formats("").any());
  EXPECT_NE(error_of([] { parse_output_formats("vtu,obj"); }).find("'obj'"), std::string::npos);
  EXPECT_NE(error_of([] { parse_output_formats("ply,ply"); }).find("twice"), std::string::npos);
}

TEST(FrameFileName, FiveDigitsThenMore) {
  EXPECT_EQ(frame_file_name(42, "vtu"), "frame_00042.vtu");
  EXPECT_EQ(frame_file_name(123456, "png"), "frame_123456.png");
}

TEST(FramesIndex, RewrittenAfterEachFrameWithTheContractHeader) {
  test::TempDir dir("frames");
  FramesIndex idx(dir / "frames.csv", {"vtu", "csv"});
  idx.add({0, 0.0, {"frame_00000.vtu", "frame_00000.csv"}});
  EXPECT_EQ(test::slurp(dir / "frames.csv"), "frame,time,vtu,csv\n0,0,frame_00000.vtu,frame_00000.csv\n");
  idx.add({1, 0.04, {"frame_00001.vtu", "frame_00001.csv"}});
  EXPECT_EQ(
      test::slurp(dir / "frames.csv"),
      "frame,time,vtu,csv\n0,0,frame_00000.vtu,frame_00000.csv\n1,0.04,frame_00001.vtu,frame_00001.csv\n");
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"frames.csv"});

  const auto back = read_frames_index(dir / "frames.csv");
  EXPECT_EQ(back.formats(), (std::vector<std::string>{"vtu", "csv"}));
  ASSERT_EQ(back.rows().size(), 2u);
  EXPECT_EQ(back.rows()[1].frame, 1u);
  EXPECT_EQ(back.rows()[1].time, 0.04);
  EXPECT_EQ(back.rows()[1].files[1], "frame_00001.csv");
}

TEST(FramesIndex, NoFormatColumnsWhenOnlyPicturesAreWritten) {
  test::TempDir dir("frames_none");
  FramesIndex idx(dir / "frames.csv", {});
  idx.add({3, 1.5, {}});
  EXPECT_EQ(test::slurp(dir / "frames.csv"), "frame,time\n3,1.5\n");
}

TEST(FramesIndex, ReaderNamesFileRowAndColumn) {
  test::TempDir dir("frames_bad");
  test::spit(dir / "a.csv", "frame,time,vtu\n0,0,a.vtu\n1,zero,b.vtu\n");
  const auto e1 = error_of([&] { read_frames_index(dir / "a.csv"); });
  EXPECT_NE(e1.find("a.csv' row 3 column 'time'"), std::string::npos) << e1;
  EXPECT_NE(e1.find("'zero'"), std::string::npos) << e1;
  test::spit(dir / "b.csv", "frame,time,csv,vtu\n");
  EXPECT_NE(error_of([&] { read_frames_index(dir / "b.csv"); }).find("unexpected column 'vtu'"),
            std::string::npos);
  test::spit(dir / "c.csv", "time,frame\n");
  EXPECT_NE(error_of([&] { read_frames_index(dir / "c.csv"); }).find("frame,time"), std::string::npos);
  test::spit(dir / "d.csv", "frame,time,ply\n0,0\n");
  EXPECT_NE(error_of([&] { read_frames_index(dir / "d.csv"); }).find("row 2: 2 columns"), std::string::npos);
}

}  // namespace
}  // namespace cellsph
