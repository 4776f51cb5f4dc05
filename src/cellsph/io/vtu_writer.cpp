#include "cellsph/io/vtu_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/io/number_format.hpp"
#include "cellsph/io/vtu_writer_impl.hpp"

namespace cellsph {

template <int Dim, class Real>
void write_vtu(const Particles<Dim, Real>& particles, double time, const std::filesystem::path& path) {
  write_vtu_any(particles, time, path);
}

template <int Dim, class Real>
void write_pvtu(const Particles<Dim, Real>& like, const std::vector<std::string>& pieces,
                const std::filesystem::path& path) {
  write_pvtu_any(like, pieces, path);
}

PvdWriter::PvdWriter(std::filesystem::path path, std::vector<PvdEntry> entries)
    : path_(std::move(path)), entries_(std::move(entries)) {}

void PvdWriter::add(double time, std::string file) {
  entries_.push_back({time, std::move(file)});
  write();
}

void PvdWriter::write() const {
  std::string s;
  s += "<?xml version=\"1.0\"?>\n";
  s += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  s += "  <Collection>\n";
  for (const auto& e : entries_) {
    s += "    <DataSet timestep=\"";
    io::append_number(s, e.time);
    s += "\" group=\"\" part=\"0\" file=\"" + io::detail::xml_escape(e.file) + "\"/>\n";
  }
  s += "  </Collection>\n";
  s += "</VTKFile>\n";
  write_file_atomic(path_, s);
}

namespace {
// Value of attribute `key` in one XML tag, or nullopt.
bool attribute(std::string_view tag, std::string_view key, std::string& value) {
  std::string pat = " ";
  pat += key;
  pat += "=\"";
  const auto a = tag.find(pat);
  if (a == std::string_view::npos) return false;
  const auto b = tag.find('"', a + pat.size());
  if (b == std::string_view::npos) return false;
  value.assign(tag.substr(a + pat.size(), b - a - pat.size()));
  return true;
}

std::string xml_unescape(std::string s) {
  const std::pair<std::string_view, char> ents[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&amp;", '&'}};
  for (const auto& [e, c] : ents) {
    for (auto p = s.find(e); p != std::string::npos; p = s.find(e, p + 1)) s.replace(p, e.size(), 1, c);
  }
  return s;
}
}  // namespace

std::vector<PvdEntry> read_pvd(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read ParaView collection '" + path.string() + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (text.find("type=\"Collection\"") == std::string::npos)
    throw InputError(std::string("'") + path.string() + "' is not a VTK Collection (.pvd) file");
  std::vector<PvdEntry> entries;
  for (auto p = text.find("<DataSet"); p != std::string::npos; p = text.find("<DataSet", p + 1)) {
    const auto end = text.find("/>", p);
    if (end == std::string::npos)
      throw InputError(std::string("'") + path.string() + "': unterminated DataSet tag");
    const std::string_view tag(text.data() + p, end - p);
    std::string t, f;
    PvdEntry e;
    if (!attribute(tag, "timestep", t) || !io::parse_number(t, e.time) || !attribute(tag, "file", f))
      throw InputError(std::string("'") + path.string() + "': DataSet " + std::to_string(entries.size()) +
                       " lacks a numeric timestep or a file");
    e.file = xml_unescape(f);
    entries.push_back(std::move(e));
  }
  return entries;
}

template void write_vtu<2, float>(const Particles<2, float>&, double, const std::filesystem::path&);
template void write_vtu<2, double>(const Particles<2, double>&, double, const std::filesystem::path&);
template void write_vtu<3, float>(const Particles<3, float>&, double, const std::filesystem::path&);
template void write_vtu<3, double>(const Particles<3, double>&, double, const std::filesystem::path&);
template void write_pvtu<2, float>(const Particles<2, float>&, const std::vector<std::string>&,
                                   const std::filesystem::path&);
template void write_pvtu<2, double>(const Particles<2, double>&, const std::vector<std::string>&,
                                    const std::filesystem::path&);
template void write_pvtu<3, float>(const Particles<3, float>&, const std::vector<std::string>&,
                                   const std::filesystem::path&);
template void write_pvtu<3, double>(const Particles<3, double>&, const std::vector<std::string>&,
                                    const std::filesystem::path&);

}  // namespace cellsph
