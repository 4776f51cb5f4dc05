// AtomicFile: a failure at any stage (open, write, fsync, close, rename) throws WriteError naming the
// target and the system's reason, leaves the target as it was and no temporary file behind.
#include "cellsph/core/atomic_file.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cellsph/core/error.hpp"

namespace cellsph {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("cellsph_atomic_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    set_write_fault(-1);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  [[nodiscard]] std::size_t entries() const {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++n;
    return n;
  }
  fs::path dir_;
};

TEST_F(AtomicFileTest, WritesLargeContentsExactly) {
  // Larger than the stream's buffer, written in pieces of odd sizes and in one block.
  std::string big;
  for (int i = 0; i < 300000; ++i) big += static_cast<char>('a' + i % 23);
  {
    AtomicFile f(dir_ / "a.bin", true);
    for (std::size_t at = 0; at < big.size(); at += 1237)
      f.stream().write(big.data() + at,
                       static_cast<std::streamsize>(std::min<std::size_t>(1237, big.size() - at)));
    f.commit();
  }
  EXPECT_EQ(slurp(dir_ / "a.bin"), big);
  write_file_atomic(dir_ / "b.bin", big);
  EXPECT_EQ(slurp(dir_ / "b.bin"), big);
  EXPECT_EQ(entries(), 2u);
}

TEST_F(AtomicFileTest, EveryFailingStageThrowsWriteErrorAndKeepsTheOldFile) {
  const std::string big(200000, 'x');  // more than one buffer: the failing write is mid-file
  for (const auto stage :
       {WriteFaultStage::Write, WriteFaultStage::Fsync, WriteFaultStage::Close, WriteFaultStage::Rename}) {
    SCOPED_TRACE(static_cast<int>(stage));
    write_file_atomic(dir_ / "t.txt", "old\n");
    set_write_fault(1, stage);
    write_file_atomic(dir_ / "first.txt", "allowed\n");  // the one file let through
    try {
      write_file_atomic(dir_ / "t.txt", big);
      ADD_FAILURE() << "no error";
    } catch (const WriteError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("'" + (dir_ / "t.txt").string() + "'"), std::string::npos) << m;
      EXPECT_NE(
          m.find(stage == WriteFaultStage::Fsync || stage == WriteFaultStage::Close ? "Input/output error"
                                                                                    : "No space left"),
          std::string::npos)
          << m;
    }
    set_write_fault(-1);
    EXPECT_EQ(slurp(dir_ / "t.txt"), "old\n");
    EXPECT_EQ(slurp(dir_ / "first.txt"), "allowed\n");
    EXPECT_EQ(entries(), 2u) << "a temporary file was left behind";
  }
}

TEST_F(AtomicFileTest, AFolderThatIsGoneIsAWriteErrorWithTheSystemsReason) {
  try {
    write_file_atomic(dir_ / "gone" / "f.txt", "x");
    ADD_FAILURE() << "no error";
  } catch (const WriteError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find((dir_ / "gone" / "f.txt").string()), std::string::npos) << m;
    EXPECT_NE(m.find("No such file or directory"), std::string::npos) << m;
  }
  EXPECT_FALSE(fs::exists(dir_ / "gone"));
}

TEST_F(AtomicFileTest, AbandonedFileLeavesNothing) {
  {
    AtomicFile f(dir_ / "never.txt");
    f.stream() << "never committed";
  }
  EXPECT_EQ(entries(), 0u);
}

TEST(AtomicTempName, RecognisesOnlyTheWritersNames) {
  EXPECT_TRUE(is_atomic_temp_name(".frame_00001.vtu.tmp1234_0"));
  EXPECT_TRUE(is_atomic_temp_name(".checkpoint.bin.tmp1_17"));
  EXPECT_FALSE(is_atomic_temp_name("frame_00001.vtu"));
  EXPECT_FALSE(is_atomic_temp_name(".frame.tmp"));
  EXPECT_FALSE(is_atomic_temp_name(".x.tmp12_"));
  EXPECT_FALSE(is_atomic_temp_name(".x.tmp_3"));
  EXPECT_FALSE(is_atomic_temp_name(".x.tmp1a_3"));
  EXPECT_FALSE(is_atomic_temp_name(".notes.tmp"));
}

}  // namespace
}  // namespace cellsph
