#pragma once
// Implementation of write_vtu(), generic over the particle type so a test can prove that any field list
// is written. Include only from vtu_writer.cpp and tests.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/io/field_types.hpp"

namespace cellsph {

static_assert(std::endian::native == std::endian::little, "the VTK writer declares LittleEndian data");

namespace io::detail {

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
    if (bytes) out.write(reinterpret_cast<const char*>(field.data()), static_cast<std::streamsize>(bytes));
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

inline std::string xml_escape(std::string_view s) {
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

}  // namespace io::detail

// The writer for any particle type with the Particles interface (x, size(), for_each_field()); the public
// write_vtu() instantiates it for Particles, tests for an extended field list.
template <class P>
void write_vtu_any(const P& particles, double time, const std::filesystem::path& path) {
  using namespace io::detail;
  io::check_field_sizes(particles);
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

// The .pvtu of one frame written as pieces (write_vtu_any, one file each): the arrays' names, types and
// components as `like` has them (its values are not read), then each piece's file. VTK's reader requires
// every piece to hold exactly the arrays declared here.
template <class P>
void write_pvtu_any(const P& like, const std::vector<std::string>& pieces,
                    const std::filesystem::path& path) {
  using namespace io::detail;
  auto declare = [](std::string& xml, std::string_view name, const auto& field) {
    using FT = io::FieldOf<std::remove_cvref_t<decltype(field)>>;
    xml += "      <PDataArray type=\"";
    xml += io::vtk_type_name<typename FT::Scalar>();
    xml += "\" Name=\"";
    xml += name;
    xml += "\" NumberOfComponents=\"" + std::to_string(vtk_components<FT>()) + "\"/>\n";
  };
  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n";
  xml +=
      "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n";
  xml += "  <PUnstructuredGrid GhostLevel=\"0\">\n";
  xml += "    <PPointData>\n";
  like.for_each_field([&](std::string_view name, const auto& field) {
    if (name != "position") declare(xml, name, field);
  });
  xml += "    </PPointData>\n";
  xml += "    <PPoints>\n";
  declare(xml, "position", like.x);
  xml += "    </PPoints>\n";
  for (const auto& piece : pieces) xml += "    <Piece Source=\"" + xml_escape(piece) + "\"/>\n";
  xml += "  </PUnstructuredGrid>\n";
  xml += "</VTKFile>\n";
  write_file_atomic(path, xml);
}

}  // namespace cellsph
