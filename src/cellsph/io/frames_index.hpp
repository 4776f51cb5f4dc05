#pragma once
// frames.csv: the index of a run's output folder, read by other tools and tests. Header
//   frame,time[,vtu][,ply][,csv]
// (format columns in that order, only those written), one row per frame holding each format's file
// name relative to the folder. Rewritten atomically after every frame, so a killed run leaves a
// complete index of the frames that exist.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace cellsph {

struct OutputFormats {
  bool vtu = false;
  bool ply = false;
  bool csv = false;
  // The canonical column order: vtu, ply, csv (only the selected ones).
  [[nodiscard]] std::vector<std::string> names() const;
  [[nodiscard]] bool any() const { return vtu || ply || csv; }
};

// Parses a --format value like "vtu,ply,csv" (any subset, any order, no repeats). `what` names the
// source in the error ("--format"). Throws InputError naming the bad item.
OutputFormats parse_output_formats(std::string_view list, std::string_view what = "--format");

// "frame_00042.vtu": the one naming rule for per-frame files (5 digits, more if needed).
std::string frame_file_name(std::size_t frame, std::string_view extension, std::string_view stem = "frame_");

struct FrameRow {
  std::size_t frame = 0;
  double time = 0;
  std::vector<std::string> files;  // one per format column, in column order
};

class FramesIndex {
 public:
  FramesIndex(std::filesystem::path path, std::vector<std::string> formats, std::vector<FrameRow> rows = {});
  // Appends a row and rewrites the file atomically. files.size() must equal formats().size().
  void add(FrameRow row);
  void write() const;
  [[nodiscard]] const std::vector<std::string>& formats() const { return formats_; }
  [[nodiscard]] const std::vector<FrameRow>& rows() const { return rows_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<std::string> formats_;
  std::vector<FrameRow> rows_;
};

// Reads a frames.csv (for --resume and for tools). Throws InputError naming the file, row and column.
FramesIndex read_frames_index(const std::filesystem::path& path);

}  // namespace cellsph
