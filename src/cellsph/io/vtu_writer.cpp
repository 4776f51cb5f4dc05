#include "cellsph/io/vtu_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/io/field_types.hpp"
#include "cellsph/io/number_format.hpp"

namespace cellsph {

static_assert(std::endian::native == std::endian::little, "the VTK writer declares LittleEndian data");

namespace {

// Number of components VTK sees: vectors are always 3 wide (z = 0 in 2D) so ParaView treats them as
// vectors (glyphs, magnitude) in both dimensions.
template <class FT>
constexpr int vtk_components() {
  return FT::is_vector ? 3 : FT::components;
}

// Writes one appended block: UInt64 byte count, then the values (vectors padded to 3 components).
template <class Vector>
void write_block(std::ostream& out, const Vector& field) {
  using FT = io::FieldOf<Vector>;
  using S = typename FT::Scalar;
  constexpr int nc = vtk_components<FT>();
  const std::uint64_t bytes = static_cast<std::uint64_t>(field.size()) * nc * sizeof(S);
  out.write(reinterpret_cast<const char*>(&bytes), sizeof(bytes));
  if constexpr (FT::components == nc) {
    // Vec<3,Real> and scalars are already laid out as VTK wants them.
    static_assert(sizeof(typename Vector::value_type) == nc * sizeof(S));
    out.write(reinterpret_cast<const char*>(field.data()), static_cast<std::streamsize>(bytes));
  } else {
    constexpr std::size_t chunk = 4096;
    std::vector<S> buf;
    buf.reserve(chunk * nc);
    for (std::size_t i0 = 0; i0 < field.size(); i0 += chunk) {
      buf.clear();
      const std::size_t i1 = std::min(field.size(), i0 + chunk);
      for (std::size_t i = i0; i < i1; ++i) {
        for (int k = 0; k < nc; ++k) buf.push_back(k < FT::components ? FT::get(field[i], k) : S(0));
      }
      out.write(reinterpret_cast<const char*>(buf.data()),
                static_cast<std::streamsize>(buf.size() * sizeof(S)));
    }
  }
}

template <class Vector>
std::uint64_t block_size(const Vector& field) {
  using FT = io::FieldOf<Vector>;
  return sizeof(std::uint64_t) +
         static_cast<std::uint64_t>(field.size()) * vtk_components<FT>() * sizeof(typename FT::Scalar);
}

// NumberOfTuples is written on every array: VTK's reader needs it on FieldData arrays (it reads zero
// tuples without it) and ignores nothing by having it elsewhere.
template <class Vector>
void data_array_tag(std::string& xml, std::string_view name, std::uint64_t offset, std::size_t tuples) {
  using FT = io::FieldOf<Vector>;
  xml += "        <DataArray type=\"";
  xml += io::vtk_type_name<typename FT::Scalar>();
  xml += "\" Name=\"";
  xml += name;
  xml += "\" NumberOfComponents=\"";
  xml += std::to_string(vtk_components<FT>());
  xml += "\" NumberOfTuples=\"";
  xml += std::to_string(tuples);
  xml += "\" format=\"appended\" offset=\"";
  xml += std::to_string(offset);
  xml += "\"/>\n";
}

std::string xml_escape(std::string_view s) {
  std::string r;
  for (const char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

}  // namespace

template <int Dim, class Real>
void write_vtu(const Particles<Dim, Real>& particles, double time, const std::filesystem::path& path) {
  const std::size_t n = particles.size();
  const std::vector<double> time_value{time};
  // Vertex cells: cell i is point i. Int64 so any particle count fits.
  std::vector<std::int64_t> connectivity(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  const std::vector<std::uint8_t> types(n, std::uint8_t{1});  // VTK_VERTEX

  // Header first: the offsets of the appended blocks follow from the field sizes alone.
  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n";
  xml +=
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n";
  xml += "  <UnstructuredGrid>\n";
  std::uint64_t offset = 0;
  xml += "    <FieldData>\n";
  data_array_tag<std::vector<double>>(xml, "TimeValue", offset, 1);
  offset += block_size(time_value);
  xml += "    </FieldData>\n";
  xml += "    <Piece NumberOfPoints=\"" + std::to_string(n) + "\" NumberOfCells=\"" + std::to_string(n) +
         "\">\n";
  xml += "      <PointData>\n";
  particles.for_each_field([&](std::string_view name, const auto& field) {
    if (name == "position") return;  // stored once, as the grid's Points
    data_array_tag<std::remove_cvref_t<decltype(field)>>(xml, name, offset, field.size());
    offset += block_size(field);
  });
  xml += "      </PointData>\n";
  xml += "      <Points>\n";
  data_array_tag<std::remove_cvref_t<decltype(particles.x)>>(xml, "position", offset, n);
  offset += block_size(particles.x);
  xml += "      </Points>\n";
  xml += "      <Cells>\n";
  data_array_tag<decltype(connectivity)>(xml, "connectivity", offset, n);
  offset += block_size(connectivity);
  data_array_tag<decltype(offsets)>(xml, "offsets", offset, n);
  offset += block_size(offsets);
  data_array_tag<decltype(types)>(xml, "types", offset, n);
  xml += "      </Cells>\n";
  xml += "    </Piece>\n";
  xml += "  </UnstructuredGrid>\n";
  xml += "  <AppendedData encoding=\"raw\">\n_";

  AtomicFile file(path, true);
  auto& out = file.stream();
  out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
  // Blocks in the order of the offsets above.
  write_block(out, time_value);
  particles.for_each_field([&](std::string_view name, const auto& field) {
    if (name != "position") write_block(out, field);
  });
  write_block(out, particles.x);
  write_block(out, connectivity);
  write_block(out, offsets);
  write_block(out, types);
  const std::string tail = "\n  </AppendedData>\n</VTKFile>\n";
  out.write(tail.data(), static_cast<std::streamsize>(tail.size()));
  file.commit();
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
    s += "\" group=\"\" part=\"0\" file=\"" + xml_escape(e.file) + "\"/>\n";
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

}  // namespace cellsph
