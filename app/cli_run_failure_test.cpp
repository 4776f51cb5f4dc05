// `cellsph run` (and `cellsph neighbors --output`) when things go wrong, on the built program:
//  - a failed start (bad scene, option, input, checkpoint, --resume folder) leaves the output location
//    exactly as it was: absent stays absent, an existing folder keeps its listing, contents and times;
//  - an output file that cannot be written stops the run with code 4 naming the file and the reason,
//    the frames written stay readable, and a resume continues bit for bit (fault injection through
//    CELLSPH_FAIL_WRITE_AFTER, core/atomic_file.hpp);
//  - SIGKILL at 20 seeded random moments, each followed by a resume, gives the uninterrupted run's
//    folder bit for bit; the same with SIGINT, each stop exiting 130 after a checkpoint; SIGTERM exits
//    143 and prints a resume command that works when pasted.
// GCC 12 reports a false -Wrestrict on chains of std::string operator+ at -O3 (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_util.hpp"

extern char** environ;

namespace {

using cellsph::test::count_lines;
using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
using cellsph::test::write_file;
namespace fs = std::filesystem;

using cellsph::test::kTiny;  // a checkpoint after every frame

// ---- folder snapshots ---------------------------------------------------------------------------------

struct Entry {
  std::string contents;  // "<dir>" for folders
  fs::file_time_type mtime;
  bool operator==(const Entry&) const = default;
};
using Snapshot = std::map<std::string, Entry>;

// Everything under `p` (p itself as ""), or nullopt when p does not exist.
std::optional<Snapshot> snapshot(const fs::path& p) {
  if (!fs::exists(fs::symlink_status(p))) return std::nullopt;
  Snapshot s;
  auto add = [&](const fs::path& e, const std::string& rel) {
    s[rel] = {fs::is_directory(e) ? std::string("<dir>") : read_file(e), fs::last_write_time(e)};
  };
  add(p, "");
  if (fs::is_directory(p))
    for (const auto& e : fs::recursive_directory_iterator(p))
      add(e.path(), fs::relative(e.path(), p).string());
  return s;
}

// The regular files under `p` by relative name, with their bytes (no times: for comparing two runs).
std::map<std::string, std::string> files_of(const fs::path& p) {
  std::map<std::string, std::string> m;
  for (const auto& e : fs::recursive_directory_iterator(p))
    if (e.is_regular_file()) m[fs::relative(e.path(), p).string()] = read_file(e.path());
  return m;
}

// Names that differ between two folders' files, for a readable failure.
std::string differences(const std::map<std::string, std::string>& a,
                        const std::map<std::string, std::string>& b) {
  std::string d;
  for (const auto& [k, v] : a)
    if (!b.count(k))
      d += " only-in-first:" + k;
    else if (b.at(k) != v)
      d += " differs:" + k;
  for (const auto& [k, v] : b)
    if (!a.count(k)) d += " only-in-second:" + k;
  return d;
}

// The lines that are not warnings (the tiny scene's weak speed of sound is warned before a fault stops it).
std::size_t count_lines_but_warnings(const std::string& s) {
  std::size_t n = 0;
  for (std::size_t at = 0; at < s.size();) {
    const std::size_t end = std::min(s.find('\n', at), s.size());
    n += s.compare(at, 18, "cellsph: warning: ") != 0;
    at = end + 1;
  }
  return n;
}

class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) { ::setenv(name, value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
};

// ---- processes ----------------------------------------------------------------------------------------

// Starts the built cellsph with `args`, stdout and stderr into `log`.
pid_t spawn_cli(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> all{cellsph::test::binary()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, cellsph::test::binary(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

// Exit code, or -signal when killed by one.
int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? -WTERMSIG(status) : -1000;
}

// Whether `pid` has installed a handler for `sig` (the SigCgt mask of /proc/PID/status).
bool catches(pid_t pid, int sig) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1u;
  return false;
}

std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> w;
  std::string cur;
  for (char c : s) {
    if (c == ' ') {
      if (!cur.empty()) w.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) w.push_back(cur);
  return w;
}

// =======================================================================================================
// 2. A failed start leaves nothing behind.

struct StartCase {
  std::string name;
  std::string args;  // after `run`; {scene} {out} are replaced
  int code;
  std::string mention;
};

std::string expand(std::string s, const fs::path& scene, const fs::path& out) {
  for (const auto& [key, value] :
       {std::pair<std::string, std::string>{"{scene}", q(scene)}, {"{out}", q(out)}}) {
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key)) s.replace(at, key.size(), value);
  }
  return s;
}

TEST(CliRunFailedStart, NewRunLeavesTheOutputLocationAsItWas) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  std::string bad_key = kTiny;
  bad_key.replace(bad_key.find("\"spacing\""), 9, "\"spacng\": 1, \"spacing\"");
  write_file(dir / "bad_key.json", bad_key);
  write_file(dir / "syntax.json", std::string(kTiny).substr(0, 200));
  std::string bad_value = kTiny;
  bad_value.replace(bad_value.find("\"dt_max\": 0.002"), 15, "\"dt_max\": -1");
  write_file(dir / "bad_value.json", bad_value);
  const std::vector<StartCase> cases = {
      {"unknown_key", q(dir / "bad_key.json") + " --out {out}", 2, "/spacng"},
      {"syntax_error", q(dir / "syntax.json") + " --out {out}", 2, "syntax.json"},
      {"bad_value", q(dir / "bad_value.json") + " --out {out}", 2, "dt_max"},
      {"missing_scene_file", q(dir / "nope.json") + " --out {out}", 2, "nope.json"},
      {"unknown_builtin", "no-such-scene --out {out}", 2, "no-such-scene"},
      {"bad_set_syntax", "{scene} --out {out} --set spacing=1", 2, "spacing=1"},
      {"bad_set_value", "{scene} --out {out} --set /solver/eos/kind=taitt", 2, "taitt"},
      {"too_many_particles", "{scene} --out {out} --set /spacing=1e-7", 2, "particles"},
      {"bad_method", "{scene} --out {out} --method octree", 2, "octree"},
      {"bad_format", "{scene} --out {out} --format vtk", 2, "vtk"},
      {"bad_color_by", "{scene} --out {out} --render --color-by taste", 2, "taste"},
      {"bad_surface_format", "{scene} --out {out} --surface --surface-format stl", 2, "stl"},
      {"bad_threads", "{scene} --out {out} --threads 0", 2, "--threads"},
      {"unknown_option", "{scene} --out {out} --frobnicate", 2, "frobnicate"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    for (const bool existing : {false, true}) {
      SCOPED_TRACE(existing ? "existing folder" : "absent folder");
      const fs::path out = dir / ("out_" + c.name + (existing ? "_existing" : ""));
      if (existing) {
        fs::create_directories(out / "sub");
        write_file(out / "keep.txt", "mine\n");
        write_file(out / "sub" / "frames.csv", "not a run\n");
      }
      const auto before = snapshot(out);
      const auto r = run_cli(dir, "run " + expand(c.args, dir / "tiny.json", out) + " --quiet");
      EXPECT_EQ(r.code, c.code) << r.err;
      EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
      EXPECT_TRUE(snapshot(out) == before) << "the output location changed";
    }
  }
  // --out naming a file: the file stays as it was.
  write_file(dir / "afile", "x\n");
  const auto before = snapshot(dir / "afile");
  const auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "afile") + " --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(snapshot(dir / "afile") == before);
}

// Mesh files are untrusted input too (geometry/mesh.hpp): an open mesh, a missing file, garbage, a
// truncated binary STL each stop the start with one line naming the scene file, the key and the mesh file.
TEST(CliRunFailedStart, BadMeshFilesLeaveTheOutputLocationAsItWas) {
  TempDir dir;
  const fs::path meshes = fs::path(cellsph::test::source_dir()) / "data" / "meshes";
  fs::create_directories(dir / "m");
  for (const char* f : {"open-cube.obj", "garbage.stl", "truncated.stl", "cube-binary.stl"})
    fs::copy_file(meshes / f, dir / "m" / f);
  write_file(dir / "box.json", R"({"name": "box", "dimension": 3, "spacing": 0.1,
    "time": {"end": 0.01},
    "fluids": [{"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}],
    "boundary": {"obstacles": [{"mesh": "m/cube-binary.stl", "scale": 0.2, "translate": [1, 1, 1]}]}})");
  const struct {
    const char* name;
    const char* mesh;
    const char* mention;
  } cases[] = {
      {"open_mesh", "m/open-cube.obj",
       "/boundary/obstacles/0/mesh: m/open-cube.obj: is not a closed surface"},
      {"missing_mesh", "m/nope.stl", "/boundary/obstacles/0/mesh: m/nope.stl: no such file"},
      {"garbage_mesh", "m/garbage.stl",
       "/boundary/obstacles/0/mesh: m/garbage.stl: binary STL header announces"},
      {"truncated_stl", "m/truncated.stl", "/boundary/obstacles/0/mesh: m/truncated.stl: binary STL"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path out = dir / (std::string("out_") + c.name);
    const auto r = run_cli(dir, "run " + q(dir / "box.json") + " --out " + q(out) +
                                    " --set /boundary/obstacles/0/mesh=" + c.mesh + " --quiet");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("box.json"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // The good mesh runs (paths resolve against the scene file, not the working folder).
  const auto r = run_cli(dir, "run " + q(dir / "box.json") + " --out " + q(dir / "ok") + " --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST(CliRunFailedStart, ResumeLeavesTheFolderAsItWas) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const fs::path run = dir / "run";
  auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(run) + " --quiet --until 0.04");
  ASSERT_EQ(r.code, 0) << r.err;
  // A temporary file of a killed writer: a successful resume removes it, a failed one must not.
  write_file(run / ".frame_00009.vtu.tmp999999999_0", "half");

  struct ResumeCase {
    std::string name;
    std::function<void(const fs::path&)> damage;
    std::string options;  // after --resume DIR
    std::string mention;
  };
  auto replace_in = [](const fs::path& f, const std::string& from, const std::string& to) {
    std::string s = read_file(f);
    const auto at = s.find(from);
    ASSERT_NE(at, std::string::npos) << from << " not in " << f;
    s.replace(at, from.size(), to);
    write_file(f, s);
  };
  const std::vector<ResumeCase> cases = {
      {"no_run_json", [](const fs::path& d) { fs::remove(d / "run.json"); }, "",
       "not a cellsph output folder"},
      {"run_json_syntax",
       [](const fs::path& d) { write_file(d / "run.json", read_file(d / "run.json").substr(0, 40)); }, "",
       "run.json"},
      {"run_json_no_options",
       [&](const fs::path& d) { replace_in(d / "run.json", "\"options\"", "\"optionz\""); }, "", "damaged"},
      {"checkpoint_checksum",
       [](const fs::path& d) {
         std::string b = read_file(d / "checkpoint.bin");
         b[b.size() - 9] = static_cast<char>(b[b.size() - 9] ^ 1);
         write_file(d / "checkpoint.bin", b);
       },
       "", "checksum mismatch"},
      {"checkpoint_truncated",
       [](const fs::path& d) {
         write_file(d / "checkpoint.bin", read_file(d / "checkpoint.bin").substr(0, 300));
       },
       "", "checkpoint"},
      {"checkpoint_old_format",
       [](const fs::path& d) {
         write_file(d / "checkpoint.bin", std::string("CSPHRUN1") + std::string(64, '\0'));
       },
       "", "earlier cellsph"},
      {"checkpoint_other_scene",
       [&](const fs::path& d) { replace_in(d / "run.json", "\"spacing\": 0.05", "\"spacing\": 0.04"); }, "",
       "particles"},
      {"frames_csv_damaged",
       [](const fs::path& d) { write_file(d / "frames.csv", "frame,time,vtu,ply,csv\n0,zero,a,b,c\n"); }, "",
       "frames.csv"},
      {"other_formats", [](const fs::path&) {}, "--format csv", "frames.csv"},
      {"set_with_resume", [](const fs::path&) {}, "--set /spacing=0.1", "--set"},
      {"bad_method", [](const fs::path&) {}, "--method octree", "octree"},
      {"bad_color_by", [](const fs::path&) {}, "--render --color-by taste", "taste"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path d = dir / ("resume_" + c.name);
    fs::copy(run, d, fs::copy_options::recursive);
    c.damage(d);
    const auto before = snapshot(d);
    r = run_cli(dir, "run --resume " + q(d) + " --until 0.1 --quiet " + c.options);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    EXPECT_TRUE(snapshot(d) == before) << "the folder changed";
  }
  // A folder that does not exist stays absent; one that is not a run stays as it was.
  r = run_cli(dir, "run --resume " + q(dir / "absent") + " --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir / "absent"));
  fs::create_directories(dir / "other");
  write_file(dir / "other" / "notes.txt", "x");
  const auto before = snapshot(dir / "other");
  r = run_cli(dir, "run --resume " + q(dir / "other") + " --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(snapshot(dir / "other") == before);
  // And the intact run resumes, removing the dead writer's temporary file.
  r = run_cli(dir, "run --resume " + q(run) + " --until 0.06 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(run / ".frame_00009.vtu.tmp999999999_0"));
  EXPECT_TRUE(fs::exists(run / "frame_00003.vtu"));
}

TEST(CliNeighborsFailedStart, OutputLocationUntouched) {
  TempDir dir;
  write_file(dir / "in.csv", "x,y\n0,0\n1,0\n");
  // An --output in a folder that does not exist: code 4 (cannot write), the folder is not created.
  auto r = run_cli(
      dir, "neighbors --input " + q(dir / "in.csv") + " --radius 2 --output " + q(dir / "nodir" / "out.csv"));
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.err.find((dir / "nodir" / "out.csv").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No such file or directory"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "nodir"));
  // A failed write (full disk, injected): code 4, one line, the earlier output untouched, no temporary.
  fs::create_directories(dir / "o");
  write_file(dir / "o" / "out.csv", "previous\n");
  const auto before = files_of(dir / "o");
  const auto mtime = fs::last_write_time(dir / "o" / "out.csv");
  {
    ScopedEnv fault("CELLSPH_FAIL_WRITE_AFTER", "0");
    r = run_cli(
        dir, "neighbors --input " + q(dir / "in.csv") + " --radius 2 --output " + q(dir / "o" / "out.csv"));
  }
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("'" + (dir / "o" / "out.csv").string() + "'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  // (The folder's own time changes: the temporary file was made and removed there.)
  EXPECT_TRUE(files_of(dir / "o") == before);
  EXPECT_TRUE(fs::last_write_time(dir / "o" / "out.csv") == mtime);
}

// =======================================================================================================
// 3. Write errors: code 4, the file and the reason named, frames kept, resume bit for bit.

TEST(CliRunWriteFailure, StopsWithCode4KeepsFramesAndResumesBitForBit) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const std::string common = " --quiet --threads 2 --until 0.1";
  auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "ref") + common);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto ref = files_of(dir / "ref");
  // Atomic files of this run: run.json, then per frame vtu, ply, csv, particles.pvd, frames.csv and the
  // checkpoint (6 frames, 36 files, and the final checkpoint). Faults from the first file to the last.
  const std::vector<std::pair<int, std::string>> faults = {
      {0, "write"}, {1, "write"},  {2, "fsync"},  {3, "close"},  {4, "rename"}, {5, "write"},
      {6, "write"}, {9, "rename"}, {13, "fsync"}, {20, "write"}, {31, "close"}, {37, "write"}};
  for (const auto& [n, stage] : faults) {
    const std::string spec = std::to_string(n) + ":" + stage;
    SCOPED_TRACE("CELLSPH_FAIL_WRITE_AFTER=" + spec);
    const fs::path out = dir / ("fault_" + std::to_string(n));
    const std::string start = "run " + q(dir / "tiny.json") + " --out " + q(out) + common;
    {
      ScopedEnv fault("CELLSPH_FAIL_WRITE_AFTER", spec);
      r = run_cli(dir, start);
    }
    EXPECT_EQ(r.code, 4) << r.err;
    EXPECT_EQ(count_lines_but_warnings(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("cannot write '" + out.string() + "/"), std::string::npos) << r.err;
    EXPECT_NE(
        r.err.find(stage == "fsync" || stage == "close" ? "Input/output error" : "No space left on device"),
        std::string::npos)
        << r.err;
    // No temporary file; every frame the index lists is complete (the reference run's bytes).
    for (const auto& [name, bytes] : files_of(out)) EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
    if (fs::exists(out / "frames.csv")) {
      const std::string index = read_file(out / "frames.csv");
      for (const auto& [name, bytes] : ref)
        if (name.rfind("frame_", 0) == 0 && index.find(name) != std::string::npos) {
          EXPECT_TRUE(read_file(out / name) == bytes) << name << " listed but not the reference's";
        }
    }
    // Space freed: the resume (or, before run.json existed, the same command again) ends like the
    // uninterrupted run, bit for bit.
    r = run_cli(dir,
                fs::exists(out / "run.json") ? "run --resume " + q(out) + " --quiet --threads 2" : start);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto got = files_of(out);
    EXPECT_TRUE(got == ref) << differences(got, ref);
  }
}

TEST(CliRunWriteFailure, PngAndSurfaceFailuresNameTheFile) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  // run.json is file 0; frame 0 writes frame_00000.csv (1), frames.csv (2), then the picture or the
  // surface (3).
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--render", "png/frame_00000.png"}, {"--surface", "surface/surface_0_00000.ply"}};
  for (const auto& [option, file] : cases) {
    SCOPED_TRACE(option);
    const fs::path out = dir / option.substr(2);
    cellsph::test::RunResult res;
    {
      ScopedEnv fault("CELLSPH_FAIL_WRITE_AFTER", "3");
      res = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(out) +
                             " --quiet --format csv --until 0.04 " + option);
    }
    EXPECT_EQ(res.code, 4) << res.err;
    EXPECT_NE(res.err.find("cannot write '" + (out / file).string() + "': No space left on device"),
              std::string::npos)
        << res.err;
    EXPECT_TRUE(fs::exists(out / "frame_00000.csv"));
    res = run_cli(dir, "run --resume " + q(out) + " --quiet");
    ASSERT_EQ(res.code, 0) << res.err;
    EXPECT_TRUE(fs::exists(out / file));
  }
}

// At 1000 frames per second and dt = 0.002 s two frames fall in one step, with a checkpoint after each:
// a run stopped between them resumes from a checkpoint whose next frame is already due. Every fault
// position through the first steps, each resumed: the same bits as the run that never failed.
TEST(CliRunWriteFailure, ResumeBetweenTwoFramesOfOneStep) {
  TempDir dir;
  std::string scene = kTiny;
  scene.replace(scene.find("\"fps\": 50"), 9, "\"fps\": 1000");
  write_file(dir / "fast.json", scene);
  const std::string common = " --quiet --threads 2 --until 0.012 --format csv";
  auto r = run_cli(dir, "run " + q(dir / "fast.json") + " --out " + q(dir / "ref") + common);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto ref = files_of(dir / "ref");
  ASSERT_NE(read_file(dir / "ref" / "frames.csv").find("\n2,0.002,"), std::string::npos)
      << "frames 1 and 2 should share a step:\n"
      << read_file(dir / "ref" / "frames.csv");
  // run.json, then per frame: frame_NNNNN.csv, frames.csv, checkpoint.bin; frames 1-2 and 3-4 share a step.
  for (int n = 1; n <= 12; ++n) {  // through frame 4 (the second step)
    SCOPED_TRACE("CELLSPH_FAIL_WRITE_AFTER=" + std::to_string(n));
    const fs::path out = dir / ("f" + std::to_string(n));
    {
      ScopedEnv fault("CELLSPH_FAIL_WRITE_AFTER", std::to_string(n));
      r = run_cli(dir, "run " + q(dir / "fast.json") + " --out " + q(out) + common);
    }
    ASSERT_EQ(r.code, 4) << r.err;
    r = run_cli(dir, "run --resume " + q(out) + " --quiet --threads 2");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto got = files_of(out);
    EXPECT_TRUE(got == ref) << differences(got, ref);
  }
}

// The folder removed under a running run: code 4 and the system's reason, not a crash.
TEST(CliRunWriteFailure, FolderRemovedUnderTheRun) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const fs::path out = dir / "run";
  const pid_t pid = spawn_cli({"run", (dir / "tiny.json").string(), "--out", out.string(), "--quiet",
                               "--until", "1", "--fps", "100", "--threads", "2"},
                              dir / "log");
  ASSERT_GT(pid, 0);
  for (int i = 0; i < 100000 && !fs::exists(out / "frames.csv"); ++i)
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  for (int i = 0; i < 1000 && fs::exists(out); ++i) {
    std::error_code ec;
    fs::remove_all(out, ec);  // may race with a file being made: try again
  }
  const int code = wait_for(pid);
  const std::string text = read_file(dir / "log");
  EXPECT_EQ(code, 4) << text;
  EXPECT_EQ(count_lines(text), 1u) << text;
  EXPECT_NE(text.find("cannot write '" + out.string() + "/"), std::string::npos) << text;
  EXPECT_NE(text.find("No such file or directory"), std::string::npos) << text;
}

// A real full disk: a 64 KiB tmpfs in a private mount namespace (unshare -rm: no privileges needed where
// the kernel allows user namespaces). Then the space is freed (remount larger) and the run resumed.
TEST(CliRunWriteFailure, RealFullDiskThenResumeWhenFreed) {
  TempDir dir;
  fs::create_directories(dir / "probe");
  write_file(dir / "probe.sh", "mount -t tmpfs -o size=64k none " + q(dir / "probe") + "\n");
  const std::string probe = "unshare -rm sh " + q(dir / "probe.sh") + " >/dev/null 2>&1";
  if (std::system(probe.c_str()) != 0)
    GTEST_SKIP() << "cannot mount a tmpfs in a private mount namespace here (unshare -rm); the injected "
                    "faults above cover this";
  write_file(dir / "tiny.json", kTiny);
  auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "ref") + " --quiet --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  fs::create_directories(dir / "mnt");
  const std::string bin = q(cellsph::test::binary()), m = q(dir / "mnt"), d = dir.path().string();
  const std::string script = "mount -t tmpfs -o size=64k none " + m + " || exit 99; " + bin + " run " +
                             q(dir / "tiny.json") + " --out " + m + "/run --quiet --threads 2 2>'" + d +
                             "/err1'; echo $? >'" + d + "/code1'; cp -r " + m + "/run '" + d +
                             "/full'; mount -o remount,size=16m " + m + " || exit 98; " + bin +
                             " run --resume " + m + "/run --quiet --threads 2 2>'" + d +
                             "/err2'; echo $? >'" + d + "/code2'; cp -r " + m + "/run '" + d + "/freed'";
  write_file(dir / "full.sh", script + "\n");
  const std::string cmd = "unshare -rm sh " + q(dir / "full.sh");
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string err1 = read_file(dir / "err1");
  EXPECT_EQ(read_file(dir / "code1"), "4\n") << err1;
  EXPECT_EQ(count_lines(err1), 1u) << err1;
  EXPECT_NE(err1.find("No space left on device"), std::string::npos) << err1;
  EXPECT_EQ(err1.find("injected"), std::string::npos) << err1;
  const auto ref = files_of(dir / "ref");
  const std::string index = read_file(dir / "full" / "frames.csv");
  int listed = 0;
  for (const auto& [name, bytes] : files_of(dir / "full")) {
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
    if (name.rfind("frame_", 0) == 0 && index.find(name) != std::string::npos) {
      ++listed;
      EXPECT_TRUE(bytes == ref.at(name)) << name;
    }
  }
  EXPECT_GT(listed, 0) << "the disk filled before the first frame: make the tmpfs larger";
  EXPECT_EQ(read_file(dir / "code2"), "0\n") << read_file(dir / "err2");
  const auto got = files_of(dir / "freed");
  EXPECT_TRUE(got == ref) << differences(got, ref);
}

// =======================================================================================================
// 4. Stop at any moment.

// A run long enough to be interrupted many times: 0.2 s at 200 frames per second (41 frames), every format.
std::vector<std::string> chain_args(const fs::path& scene, const fs::path& out) {
  return {"run", scene.string(), "--out", out.string(), "--quiet", "--threads",
          "2",   "--until",      "0.2",   "--fps",      "200"};
}

// Waits until `pid` has installed its SIGINT handler (the first thing `cellsph run` does, before it
// reads the scene), so the time before, the program loader's, is left out of the random moments.
bool wait_until_started(pid_t pid) {
  for (int i = 0; i < 100000; ++i) {
    if (catches(pid, SIGINT)) return true;
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return false;
}

// Frames listed in DIR/frames.csv (0 when there is none yet).
std::size_t listed_frames(const fs::path& out) {
  const std::size_t n = count_lines(read_file(out / "frames.csv"));
  return n ? n - 1 : 0;
}

// Interrupts the run in `out` 20 times with `sig`, starting it again each time (--resume once run.json
// exists), then lets it finish. The moments are seeded and tied to the run's progress, not to the
// clock, so they spread over the run whatever the machine's load: each time, once the run has listed
// 0, 1 or 2 more frames than before it started, plus 0-2 ms (into the steps and the frame and checkpoint
// writes that follow). Returns how many signals hit a running process.
int interrupt_chain(const TempDir& dir, const fs::path& scene, const fs::path& out, int sig, unsigned seed,
                    int& mid_write) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> more(0, 2);
  std::uniform_real_distribution<double> delay(0.0, 0.002);
  auto next_args = [&] {
    return fs::exists(out / "run.json")
               ? std::vector<std::string>{"run", "--resume", out.string(), "--quiet", "--threads", "2"}
               : chain_args(scene, out);
  };
  int landed = 0;
  for (int k = 0; k < 20; ++k) {
    const std::size_t target = listed_frames(out) + more(rng);
    const double extra = delay(rng);
    const fs::path log = dir / ("log_" + std::to_string(k));
    const pid_t pid = spawn_cli(next_args(), log);
    EXPECT_GT(pid, 0);
    if (pid <= 0) return landed;
    if (!wait_until_started(pid)) {
      ADD_FAILURE() << "ended before it started the run: " << read_file(log);
      return landed;
    }
    for (int i = 0; i < 300000 && listed_frames(out) < target; ++i) {
      siginfo_t info{};
      if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
          info.si_pid == pid)
        break;  // ended (reaped below)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(extra));
    ::kill(pid, sig);
    const int code = wait_for(pid);
    const std::string text = read_file(log);
    if (sig == SIGKILL) {
      EXPECT_TRUE(code == -SIGKILL || code == 0) << "code " << code << ": " << text;
      landed += code == -SIGKILL;
      if (fs::exists(out))
        for (const auto& e : fs::directory_iterator(out))
          if (e.path().filename().string().find(".tmp") != std::string::npos) {
            ++mid_write;  // killed while writing a file: its temporary is left, the resume removes it
            break;
          }
    } else {
      // 0 only when the run had already ended when the signal came.
      EXPECT_TRUE(code == 128 + sig || code == 0) << "code " << code << ": " << text;
      if (code == 128 + sig) {
        ++landed;
        EXPECT_TRUE(text.find("to continue: ") != std::string::npos ||
                    text.find("before the run started; nothing was written") != std::string::npos)
            << text;
      }
    }
  }
  const pid_t pid = spawn_cli(next_args(), dir / "log_last");
  EXPECT_EQ(wait_for(pid), 0) << read_file(dir / "log_last");
  return landed;
}

class CliRunInterrupted : public ::testing::TestWithParam<int> {};

TEST_P(CliRunInterrupted, TwentyTimesThenResumedEqualsTheUninterruptedRun) {
  const int sig = GetParam();
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const pid_t pid = spawn_cli(chain_args(dir / "tiny.json", dir / "ref"), dir / "ref.log");
  ASSERT_EQ(wait_for(pid), 0) << read_file(dir / "ref.log");
  const auto ref = files_of(dir / "ref");
  int mid_write = 0;
  const int landed = interrupt_chain(dir, dir / "tiny.json", dir / "chain", sig, 20261201u + sig, mid_write);
  const auto got = files_of(dir / "chain");
  EXPECT_TRUE(got == ref) << differences(got, ref);
  EXPECT_GE(landed, 15) << "too few signals hit a running process";
  std::printf("[ info ] %d of 20 signals %d hit a running process", landed, sig);
  if (sig == SIGKILL) std::printf(", %d of them while it wrote a file (a temporary left)", mid_write);
  std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(Signals, CliRunInterrupted, ::testing::Values(SIGKILL, SIGINT), [](const auto& p) {
  return p.param == SIGKILL ? std::string("SIGKILL") : std::string("SIGINT");
});

TEST(CliRunInterrupted, SigtermExits143AndPrintsAResumeCommandThatWorks) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  auto r = run_cli(
      dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "ref") + " --quiet --threads 2 --until 0.2");
  ASSERT_EQ(r.code, 0) << r.err;
  // Resumed with an explicit --until: the printed command must carry it (run.json keeps 0.1).
  r = run_cli(
      dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "run") + " --quiet --threads 2 --until 0.1");
  ASSERT_EQ(r.code, 0) << r.err;
  const pid_t pid =
      spawn_cli({"run", "--resume", (dir / "run").string(), "--until", "0.2", "--threads", "2"}, dir / "log");
  // Once the resumed run has written its first frame (frame 6, t = 0.12 s; 4 frames to go).
  for (int i = 0; i < 300000 && listed_frames(dir / "run") < 7; ++i)
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  ::kill(pid, SIGTERM);
  const int code = wait_for(pid);
  const std::string text = read_file(dir / "log");
  ASSERT_EQ(code, 143) << text;
  EXPECT_NE(text.find("stopped by SIGTERM at t = "), std::string::npos) << text;
  EXPECT_NE(text.find((dir / "run").string()), std::string::npos) << text;
  const auto at = text.find("to continue: ");
  ASSERT_NE(at, std::string::npos) << text;
  const std::string command = text.substr(at + 13, text.find('\n', at) - at - 13);
  const auto w = words(command);
  ASSERT_GE(w.size(), 4u) << command;
  EXPECT_EQ(w[1], "run");
  EXPECT_EQ(w[2], "--resume");
  EXPECT_NE(command.find("--until 0.2"), std::string::npos) << command;
  EXPECT_NE(command.find("--threads 2"), std::string::npos) << command;
  // Pasted (with the built binary in place of the name it was started as).
  r = run_cli(dir, command.substr(w[0].size()) + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_file(dir / "run" / "frame_00010.csv") == read_file(dir / "ref" / "frame_00010.csv"));
  EXPECT_EQ(read_file(dir / "run" / "frames.csv"), read_file(dir / "ref" / "frames.csv"));
}

// =======================================================================================================
// 5. One checkpoint format: a run folder written by format 1 (data/checkpoints/) still resumes, and
// continues to what a fresh run computes.

std::vector<double> numbers(const std::string& csv) {
  std::vector<double> v;
  std::string cell;
  bool header = true;
  for (char c : csv) {
    if (c == ',' || c == '\n') {
      if (!header && !cell.empty()) v.push_back(std::stod(cell));
      cell.clear();
      if (c == '\n') header = false;
    } else {
      cell += c;
    }
  }
  return v;
}

TEST(CliRunCheckpointFormat, AVersion1RunFolderStillResumes) {
  TempDir dir;
  fs::copy(fs::path(cellsph::test::source_dir()) / "data" / "checkpoints" / "v1-tiny-2d", dir / "old",
           fs::copy_options::recursive);
  auto r = run_cli(dir, "run --resume " + q(dir / "old") + " --until 0.1 --threads 2 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "old" / "frame_00002.csv"))
      << "frames before the checkpoint are not rewritten";
  write_file(dir / "tiny.json", kTiny);
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "new") +
                       " --format csv --until 0.1 --threads 2 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  // Equal numbers (within rounding: the folder was written by another build, which may round
  // differently; the same build gives the same bits, CliRun.ResumeContinuesBitForBit).
  const auto a = numbers(read_file(dir / "old" / "frame_00005.csv"));
  const auto b = numbers(read_file(dir / "new" / "frame_00005.csv"));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  for (std::size_t k = 0; k < a.size(); ++k)
    EXPECT_NEAR(a[k], b[k], 1e-9 * (1 + std::abs(b[k]))) << "value " << k;
}

}  // namespace
