#include "cellsph/render/video.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

#include "cellsph/io/number_format.hpp"

extern char** environ;  // NOLINT: POSIX

namespace cellsph {

std::optional<std::filesystem::path> find_on_path(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    if (::access(program.c_str(), X_OK) == 0) return std::filesystem::path(program);
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  const std::string dirs(path);
  std::size_t a = 0;
  while (a <= dirs.size()) {
    auto b = dirs.find(':', a);
    if (b == std::string::npos) b = dirs.size();
    const std::string dir = b > a ? dirs.substr(a, b - a) : std::string(".");
    const auto candidate = std::filesystem::path(dir) / program;
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
    a = b + 1;
  }
  return std::nullopt;
}

VideoResult make_mp4(const std::filesystem::path& frames_dir, const std::string& pattern, double fps,
                     const std::filesystem::path& mp4, const std::string& ffmpeg) {
  const auto exe = find_on_path(ffmpeg);
  if (!exe)
    return {false, std::string("no MP4 written: '") + ffmpeg +
                       "' not found on PATH (install it, e.g. apt-get install ffmpeg); "
                       "the PNG frames are in '" +
                       frames_dir.string() + "'"};
  if (!(fps > 0))
    return {false, std::string("no MP4 written: frame rate must be positive, got ") + io::number_text(fps)};
  // ffmpeg picks the container from the extension, so the temporary name keeps ".mp4".
  const auto tmp = mp4.parent_path() /
                   (std::string(".") + mp4.stem().string() + ".tmp" + std::to_string(::getpid()) + ".mp4");
  std::vector<std::string> args = {exe->string(), "-y",
                                   "-loglevel",   "error",
                                   "-framerate",  io::number_text(fps),
                                   "-i",          (frames_dir / pattern).string(),
                                   "-vf",         "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",        "libx264",
                                   "-pix_fmt",    "yuv420p",
                                   tmp.string()};
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int err = ::posix_spawn(&pid, exe->c_str(), nullptr, nullptr, argv.data(), environ); err != 0)
    return {false, std::string("no MP4 written: cannot start '") + exe->string() + "' (error " +
                       std::to_string(err) + ")"};
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    return {false, std::string("no MP4 written: ffmpeg failed (exit status ") +
                       std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ") on '" +
                       (frames_dir / pattern).string() + "'"};
  }
  std::error_code ec;
  std::filesystem::rename(tmp, mp4, ec);
  if (ec)
    return {false, std::string("no MP4 written: cannot rename '") + tmp.string() + "': " + ec.message()};
  return {true, std::string("wrote ") + mp4.string()};
}

}  // namespace cellsph
