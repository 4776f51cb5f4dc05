#pragma once
// Frames to MP4 through ffmpeg, if it is installed. Rendering never depends on it: without ffmpeg the
// result says so and the PNG frames stay usable.
#include <filesystem>
#include <optional>
#include <string>

namespace cellsph {

// Full path of an executable found on PATH, or nullopt.
std::optional<std::filesystem::path> find_on_path(const std::string& program);

struct VideoResult {
  bool ok = false;
  std::string message;  // what happened, fit for the user (e.g. "ffmpeg not found on PATH; ...")
};

// Runs `ffmpeg -framerate F -i DIR/PATTERN -c:v libx264 -pix_fmt yuv420p` (padding odd sizes to even),
// into a temporary file beside `mp4` that is renamed over it on success. `ffmpeg` names the program.
VideoResult make_mp4(const std::filesystem::path& frames_dir, const std::string& pattern, double fps,
                     const std::filesystem::path& mp4, const std::string& ffmpeg = "ffmpeg");

}  // namespace cellsph
