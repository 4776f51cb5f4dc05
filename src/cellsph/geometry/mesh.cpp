#include "cellsph/geometry/mesh.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#ifndef CELLSPH_NO_ASSIMP  // the GPU check's build (cmake/gpu_check.cmake): no Assimp on that machine
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#endif

#include "cellsph/core/error.hpp"

namespace cellsph::geometry {

namespace {

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string point_text(const P3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
  return buf;
}

[[noreturn]] void fail(const std::string& label, const std::string& what) {
  throw InputError(label + ": " + what);
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Assimp decides between binary and ASCII STL as we do here, but says only "Failed to determine STL
// storage representation"; a truncated binary file deserves its sizes in the message. Binary: an 80-byte
// header, a 32-bit little-endian triangle count C, then exactly 50 bytes per triangle.
void check_stl(std::string_view b, const std::string& label) {
  if (b.size() >= 84) {
    std::uint32_t count = 0;
    for (int k = 3; k >= 0; --k)
      count = (count << 8) | static_cast<unsigned char>(b[80 + static_cast<std::size_t>(k)]);
    if (84 + 50 * std::uint64_t{count} == b.size()) return;  // binary
  }
  std::size_t i = 0;
  while (i < b.size() && std::isspace(static_cast<unsigned char>(b[i]))) ++i;
  if (b.substr(i, 5) == "solid") {
    // ASCII: text only (Assimp's own test looks at the first bytes; we look at all of them).
    for (std::size_t k = 0; k < b.size(); ++k) {
      const auto c = static_cast<unsigned char>(b[k]);
      if (c == 0 || c >= 0x80)
        fail(label, "starts like an ASCII STL file (\"solid\") but byte " + std::to_string(k) +
                        " is not text, and its size (" + std::to_string(b.size()) +
                        " bytes) is not that of a binary STL file");
    }
    return;
  }
  if (b.size() < 84)
    fail(label, "is neither an ASCII STL file (it does not start with \"solid\") nor a binary one (" +
                    std::to_string(b.size()) + " bytes, fewer than the 84 of a binary STL header)");
  std::uint32_t count = 0;
  for (int k = 3; k >= 0; --k)
    count = (count << 8) | static_cast<unsigned char>(b[80 + static_cast<std::size_t>(k)]);
  fail(label, "binary STL header announces " + std::to_string(count) + " triangles (" +
                  std::to_string(84 + 50 * std::uint64_t{count}) + " bytes) but the file has " +
                  std::to_string(b.size()) + " bytes: truncated, or not an STL file");
}

// Assimp's PLY reader reserves memory for the counts the header announces before reading the data (a
// 40-byte header announcing 10^12 vertices would ask for terabytes), and loops without end on some headers
// it cannot parse (one whose "end_header" is inside a comment: fuzz/regressions/mesh/ply-end-header-in-
// comment). So the header must be well formed before Assimp sees it: "ply", a "format" line, then only
// comment, obj_info, element and property lines up to a line "end_header"; an "element vertex" and an
// "element face"; and the counts no more than the bytes after the header (every element takes at least one).
// Each element name once: a second "element vertex" made Assimp 5.2.5 free memory twice
// (fuzz/regressions/mesh/ply-element-declared-twice). Each property after an element, of a PLY type, with
// a name (a list: "property list COUNT_TYPE ITEM_TYPE NAME").
bool ply_type(std::string_view t) {
  static constexpr std::string_view kTypes[] = {"char",  "uchar",  "short",   "ushort", "int",   "uint",
                                                "float", "double", "int8",    "uint8",  "int16", "uint16",
                                                "int32", "uint32", "float32", "float64"};
  return std::find(std::begin(kTypes), std::end(kTypes), t) != std::end(kTypes);
}

std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> w;
  std::size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
    const std::size_t start = k;
    while (k < line.size() && line[k] != ' ' && line[k] != '\t') ++k;
    if (k > start) w.push_back(line.substr(start, k - start));
  }
  return w;
}

void check_ply(std::string_view b, const std::string& label) {
  std::size_t pos = 0, line_no = 0, data = 0;
  double total = 0;
  bool vertex = false, face = false, ended = false, ascii = false;
  std::vector<std::string> elements;
  while (pos < b.size() && !ended) {
    std::size_t nl = b.find('\n', pos);
    if (nl == std::string_view::npos) nl = b.size();
    std::string_view line = b.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string where = "PLY header line " + std::to_string(line_no);
    auto word = [&](std::string_view w) {
      return line.substr(0, w.size()) == w && (line.size() == w.size() || line[w.size()] == ' ');
    };
    if (line_no == 1) {
      if (line != "ply") fail(label, "is not a PLY file (its first line is not \"ply\")");
    } else if (line_no == 2) {
      if (!word("format")) fail(label, where + ": expected \"format ...\"");
      ascii = word("format ascii");
    } else if (line == "end_header") {
      ended = true;
      data = b.size() - std::min(b.size(), pos);
    } else if (word("element")) {
      const auto w = words_of(line);
      bool digits = w.size() == 3;
      double count = 0;
      for (std::size_t k = 0; digits && k < w[2].size(); ++k) {
        if (w[2][k] < '0' || w[2][k] > '9') digits = false;
        count = count * 10 + (w[2][k] - '0');
      }
      if (!digits) fail(label, where + ": an element needs a name and a count");
      if (std::find(elements.begin(), elements.end(), w[1]) != elements.end())
        fail(label, where + ": element \"" + std::string(w[1]) + "\" is declared twice");
      elements.emplace_back(w[1]);
      vertex = vertex || word("element vertex");
      face = face || word("element face");
      total += count;
    } else if (word("property")) {
      const auto w = words_of(line);
      const bool list = w.size() > 1 && w[1] == "list";
      const bool ok =
          list ? w.size() == 5 && ply_type(w[2]) && ply_type(w[3]) : w.size() == 3 && ply_type(w[1]);
      if (!ok)
        fail(label,
             where + ": \"" + std::string(line.substr(0, 40)) +
                 "\" is not \"property TYPE NAME\" or \"property list TYPE TYPE NAME\" with PLY types");
      if (elements.empty()) fail(label, where + ": a property before any element");
    } else if (!word("comment") && !word("obj_info")) {
      fail(label, where + ": unexpected \"" + std::string(line.substr(0, 40)) + "\" in the header");
    }
  }
  if (!ended) fail(label, "PLY header has no end_header line");
  if (!vertex || !face) fail(label, "PLY header announces no \"element vertex\" or no \"element face\"");
  if (total > double(data))
    fail(label, "PLY header announces " + num(total) + " elements but only " + std::to_string(data) +
                    " bytes follow it: truncated, or not a PLY file");
  // An ASCII PLY's data is text: numbers and white space. A control byte in it made Assimp 5.2.5's
  // reader take over 2 GB on a 271-byte file (fuzz/regressions/mesh/ply-control-byte-in-ascii-data).
  if (ascii)
    for (std::size_t k = b.size() - data; k < b.size(); ++k) {
      const auto c = static_cast<unsigned char>(b[k]);
      if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c >= 0x7f)
        fail(label, "byte " + std::to_string(k) + " of the ASCII PLY data is not text (code " +
                        std::to_string(c) + ")");
    }
}

#ifndef CELLSPH_NO_ASSIMP
// Reads `bytes` from memory with the extension as the hint: only that format's reader runs, and an OBJ
// file's "mtllib" cannot make Assimp open other files (there are none in its memory file system).
const aiScene* import_scene(Assimp::Importer& importer, std::string_view bytes, const std::string& ext,
                            const std::string& label) {
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  const aiScene* scene = nullptr;
  try {
    // No aiProcess_Triangulate: Debian's Assimp 5.2.5 aborts in it (an ai_assert) on some polygon
    // lists (fuzz/regressions/mesh/assimp-triangulate-abort); polygons are split by add_faces, as fans.
    scene =
        importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_ValidateDataStructure, ext.c_str());
  } catch (const std::exception& e) {
    fail(label, std::string("cannot be read as ") + ext + ": " + e.what());
  }
  if (!scene) {
    std::string why = importer.GetErrorString();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    fail(label, "cannot be read as " + ext + " (Assimp: " + (why.empty() ? "no reason given" : why) + ")");
  }
  return scene;
}

// A vertex position as Assimp holds it: equal positions are one vertex of the welded mesh.
struct VertexKey {
  float x, y, z;
  bool operator==(const VertexKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct VertexKeyHash {
  std::size_t operator()(const VertexKey& k) const {
    std::uint32_t b[3];
    std::memcpy(b, &k, sizeof b);
    return (std::size_t{b[0]} * 0x9E3779B1u) ^ (std::size_t{b[1]} * 0x85EBCA77u) ^
           (std::size_t{b[2]} * 0xC2B2AE3Du) ^ (std::size_t{b[2]} << 32);
  }
};
using WeldIndex = std::unordered_map<VertexKey, std::uint32_t, VertexKeyHash>;

// Adds the faces of one of Assimp's meshes to `m`: a polygon of n vertices as the fan of n - 2 triangles
// from its first vertex, on vertices welded by position (`index`: each position's vertex in `m`). Returns
// the faces that are points or lines.
std::size_t add_faces(const aiMesh& am, TriangleMesh& m, WeldIndex& index, const std::string& label) {
  std::size_t lines_or_points = 0;
  std::vector<std::uint32_t> local(am.mNumVertices, std::numeric_limits<std::uint32_t>::max());
  auto vertex = [&](unsigned v) -> std::uint32_t {
    if (v >= am.mNumVertices)
      fail(label, "a face refers to vertex " + std::to_string(v) + " of " + std::to_string(am.mNumVertices));
    if (local[v] != std::numeric_limits<std::uint32_t>::max()) return local[v];
    const aiVector3D& a = am.mVertices[v];
    if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(a.z))
      fail(label, "vertex " + std::to_string(v + 1) + " has a coordinate that is not a finite number");
    const VertexKey k{a.x + 0.0f, a.y + 0.0f, a.z + 0.0f};  // + 0: -0 and 0 are one vertex
    auto [it, added] = index.try_emplace(k, static_cast<std::uint32_t>(m.vertices.size()));
    if (added) m.vertices.push_back({double(a.x), double(a.y), double(a.z)});
    return local[v] = it->second;
  };
  if (am.mNumFaces > 0 && !am.mFaces) fail(label, "a mesh has faces but no face list");
  for (unsigned f = 0; f < am.mNumFaces; ++f) {
    const aiFace& face = am.mFaces[f];
    if (face.mNumIndices < 3 || !face.mIndices) {
      ++lines_or_points;
      continue;
    }
    const std::uint32_t first = vertex(face.mIndices[0]);
    for (unsigned k = 1; k + 1 < face.mNumIndices; ++k)
      m.triangles.push_back({first, vertex(face.mIndices[k]), vertex(face.mIndices[k + 1])});
  }
  return lines_or_points;
}
#endif
}  // namespace

TriangleMesh read_mesh_file(const std::filesystem::path& file, const std::string& label) {
  const std::string ext = lower(file.extension().string());
  if (ext != ".stl" && ext != ".obj" && ext != ".ply")
    fail(label, "unknown mesh format \"" + file.extension().string() + "\" (expected .stl, .obj or .ply)");
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status)) fail(label, "no such file");
  if (std::filesystem::is_directory(status)) fail(label, "is a folder, not a mesh file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(label, std::string("cannot be opened: ") + std::strerror(errno));
  std::string bytes;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    bytes.append(buf, static_cast<std::size_t>(in.gcount()));
    if (bytes.size() > kMaxFileBytes) fail(label, "is larger than 1 GiB");
  }
  if (in.bad()) fail(label, "read error");
  return parse_mesh(bytes, ext.substr(1), label);
}

TriangleMesh parse_mesh(std::string_view bytes, std::string_view extension, const std::string& label) {
  const std::string ext = lower(extension);
  if (ext != "stl" && ext != "obj" && ext != "ply")
    fail(label, "unknown mesh format \"" + std::string(extension) + "\" (expected stl, obj or ply)");
  if (bytes.empty()) fail(label, "is empty");
  if (ext == "stl") check_stl(bytes, label);
  if (ext == "ply") check_ply(bytes, label);
#ifdef CELLSPH_NO_ASSIMP
  fail(label, "cannot be read: this build of cellsph has no mesh reader (built without Assimp)");
#else
  Assimp::Importer importer;
  const aiScene* scene = import_scene(importer, bytes, ext, label);
  // The meshes of the file as one: their triangles on vertices welded across them.
  TriangleMesh m;
  WeldIndex index;
  std::size_t lines_or_points = 0;
  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi)
    if (const aiMesh* am = scene->mMeshes[mi]) lines_or_points += add_faces(*am, m, index, label);
  if (m.triangles.empty())
    fail(label, lines_or_points ? "has only points or lines, no triangles (a closed surface is needed)"
                                : "has no triangles");
  if (lines_or_points)
    fail(label, "has " + std::to_string(lines_or_points) +
                    " points or lines besides its triangles (a closed surface of triangles is needed)");
  return m;
#endif
}

void transform(TriangleMesh& m, const MeshTransform& t) {
  double len = std::sqrt(t.axis[0] * t.axis[0] + t.axis[1] * t.axis[1] + t.axis[2] * t.axis[2]);
  const P3 u{t.axis[0] / len, t.axis[1] / len, t.axis[2] / len};
  const double a = t.angle_deg * M_PI / 180, c = std::cos(a), s = std::sin(a);
  for (auto& p : m.vertices) {
    const P3 q{p[0] * t.scale, p[1] * t.scale, p[2] * t.scale};
    // Rodrigues: q cos + (u x q) sin + u (u . q)(1 - cos)
    const double d = u[0] * q[0] + u[1] * q[1] + u[2] * q[2];
    const P3 x{u[1] * q[2] - u[2] * q[1], u[2] * q[0] - u[0] * q[2], u[0] * q[1] - u[1] * q[0]};
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<std::size_t>(k);
      p[i] = q[i] * c + x[i] * s + u[i] * d * (1 - c) + t.translate[i];
    }
  }
}

double volume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) {
    const P3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

void bounds(const TriangleMesh& m, P3& lo, P3& hi) {
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& p : m.vertices)
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
}

void check_closed(TriangleMesh& m, const std::string& label) {
  // Triangles with a repeated vertex enclose nothing and share no edge: drop them.
  std::erase_if(m.triangles, [](const auto& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; });
  if (m.triangles.empty()) fail(label, "has only degenerate triangles (each with a repeated vertex)");
  struct Edge {
    std::uint32_t lo, hi, tri;
    bool forward;  // traversed lo -> hi
  };
  std::vector<Edge> edges;
  edges.reserve(3 * m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = m.triangles[t][static_cast<std::size_t>(k)],
                          b = m.triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(t), a < b});
    }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.tri < y.tri;
  });
  // The bad edge group whose first triangle comes first in the file.
  std::size_t bad = edges.size(), bad_end = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    const bool ok = j - i == 2 && edges[i].forward != edges[i + 1].forward;
    if (!ok && (bad == edges.size() || edges[i].tri < edges[bad].tri)) {
      bad = i;
      bad_end = j;
    }
    i = j;
  }
  if (bad < edges.size()) {
    const Edge& e = edges[bad];
    const std::string which =
        "the edge from " + point_text(m.vertices[e.lo]) + " to " + point_text(m.vertices[e.hi]);
    const std::size_t n = bad_end - bad;
    if (n == 1)
      fail(label, "is not a closed surface: " + which + " belongs to triangle " + std::to_string(e.tri + 1) +
                      " only (a closed surface has every edge in exactly two triangles)");
    if (n > 2)
      fail(label, "is not a closed surface: " + which + " belongs to " + std::to_string(n) + " triangles (" +
                      std::to_string(e.tri + 1) + ", " + std::to_string(edges[bad + 1].tri + 1) +
                      ", ...); a closed surface has every edge in exactly two");
    fail(label, "is not consistently oriented: triangles " + std::to_string(e.tri + 1) + " and " +
                    std::to_string(edges[bad + 1].tri + 1) + " both run along " + which +
                    " in the same direction (one of them faces the wrong way)");
  }
  double v = volume(m);
  P3 lo, hi;
  bounds(m, lo, hi);
  double diag = 0;
  for (std::size_t a = 0; a < 3; ++a) diag = std::max(diag, hi[a] - lo[a]);
  if (!(std::abs(v) > 1e-9 * diag * diag * diag))
    fail(label,
         "encloses zero volume (" + num(v) + ", bounds " + point_text(lo) + " to " + point_text(hi) + ")");
  if (v < 0)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
}

}  // namespace cellsph::geometry
