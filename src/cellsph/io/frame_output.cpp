#include "cellsph/io/frame_output.hpp"

#include <set>

#include "cellsph/core/error.hpp"
#include "cellsph/io/ply_writer.hpp"

namespace cellsph {

template <int Dim, class Real>
FrameOutput<Dim, Real>::FrameOutput(std::filesystem::path dir, OutputFormats formats, CsvRowFilter fluid,
                                    std::string pvd_name)
    : dir_(std::move(dir)),
      formats_(formats),
      fluid_(std::move(fluid)),
      index_(dir_ / "frames.csv", formats.names()),
      pvd_(dir_ / pvd_name) {}

template <int Dim, class Real>
void FrameOutput<Dim, Real>::resume(std::size_t next_frame) {
  const auto index_path = dir_ / "frames.csv";
  std::vector<FrameRow> rows;
  if (std::filesystem::exists(index_path)) {
    const FramesIndex old = read_frames_index(index_path);
    if (old.formats() != index_.formats()) {
      std::string have, want;
      for (const auto& f : old.formats()) have += (have.empty() ? "" : ",") + f;
      for (const auto& f : index_.formats()) want += (want.empty() ? "" : ",") + f;
      throw InputError(std::string("'") + index_path.string() + "' lists formats '" + have +
                       "' but this run writes '" + want + "'");
    }
    for (const auto& r : old.rows())
      if (r.frame < next_frame) rows.push_back(r);
  }
  std::vector<PvdEntry> entries;
  if (formats_.vtu && std::filesystem::exists(pvd_.path())) {
    std::set<std::string> kept;
    for (const auto& r : rows) kept.insert(r.files.front());  // vtu is the first column when written
    for (auto& e : read_pvd(pvd_.path()))
      if (kept.count(e.file)) entries.push_back(std::move(e));
  }
  index_ = FramesIndex(index_path, index_.formats(), std::move(rows));
  pvd_ = PvdWriter(pvd_.path(), std::move(entries));
}

template <int Dim, class Real>
std::vector<std::filesystem::path> FrameOutput<Dim, Real>::write(const Particles<Dim, Real>& particles,
                                                                 std::size_t frame, double time) {
  if (!dir_made_) {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) throw WriteError("cannot create output folder '" + dir_.string() + "': " + ec.message());
    dir_made_ = true;
  }
  std::vector<std::filesystem::path> written;
  FrameRow row{frame, time, {}};
  const Particles<Dim, Real>* out = &particles;
  CsvRowFilter keep = fluid_;
  if (!in_id_order(particles)) {
    copy_in_id_order(particles, ordered_, from_);
    out = &ordered_;
    if (fluid_) keep = [this](std::size_t k) { return fluid_(from_[k]); };
  }
  // Frame files first, the indexes last: an index never names a file that is not complete.
  if (formats_.vtu) {
    row.files.push_back(frame_file_name(frame, "vtu"));
    write_vtu(*out, time, dir_ / row.files.back());
    written.push_back(dir_ / row.files.back());
  }
  if (formats_.ply) {
    row.files.push_back(frame_file_name(frame, "ply"));
    write_ply(*out, time, dir_ / row.files.back());
    written.push_back(dir_ / row.files.back());
  }
  if (formats_.csv) {
    row.files.push_back(frame_file_name(frame, "csv"));
    write_csv(*out, dir_ / row.files.back(), keep);
    written.push_back(dir_ / row.files.back());
  }
  if (formats_.vtu) pvd_.add(time, row.files.front());
  index_.add(std::move(row));
  return written;
}

template class FrameOutput<2, float>;
template class FrameOutput<2, double>;
template class FrameOutput<3, float>;
template class FrameOutput<3, double>;

}  // namespace cellsph
