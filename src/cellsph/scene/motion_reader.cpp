// boundary.obstacles[k].motion (docs/scenes.md, "Moving obstacles"): one of translate, rotate, oscillate
// or a table of positions read from a CSV file beside the scene.
#include "cellsph/scene/scene_readers.hpp"

#include <cmath>
#include <fstream>
#include <system_error>

namespace cellsph::scene_detail {

namespace {

// A unit vector of `dim` components at `key` (z = 0 in 2D); the zero vector is an error.
void read_unit(JsonReader& r, const std::string& key, std::size_t dim, double (&out)[3]) {
  const auto v = r.required_vector(key, dim);
  double len = 0;
  for (const double c : v) len += c * c;
  len = std::sqrt(len);
  if (!(len > 0) || !std::isfinite(len)) r.fail(key, "must be a non-zero vector");
  for (std::size_t a = 0; a < 3; ++a) out[a] = a < dim ? v[a] / len : 0.0;
}

// A motion table's text: a file beside the scene (at most 64 MiB); built-in scenes have none.
std::string read_motion_table_file(JsonReader& m, const std::string& name, const MeshFiles& files) {
  if (name.empty()) m.fail("table", "must name a CSV file (columns time,x,y[,z][,angle])");
  if (files.builtin) m.fail("table", "built-in scenes cannot read motion tables");
  const std::filesystem::path p(name);
  const std::filesystem::path file = p.is_absolute() ? p : files.dir / p;
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status)) m.fail("table", name + ": no such file");
  if (std::filesystem::is_directory(status)) m.fail("table", name + ": is a folder, not a CSV file");
  std::ifstream in(file, std::ios::binary);
  if (!in) m.fail("table", name + ": cannot be opened");
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > (std::size_t{64} << 20)) m.fail("table", name + ": is larger than 64 MiB");
  }
  if (in.bad()) m.fail("table", name + ": read error");
  return text;
}

}  // namespace

template <int Dim, class Real>
std::int32_t read_motion(JsonReader& e, const MeshFiles& files, SolverConfig<Dim, Real>& cfg) {
  auto mr = e.child("motion");
  if (!mr.json().is_object()) mr.fail_here("expected an object, got " + json_value_text(mr.json()));
  const char* kinds[] = {"translate", "rotate", "oscillate", "table"};
  int given = 0;
  for (const char* k : kinds) given += mr.has(k) ? 1 : 0;
  if (given != 1) {
    std::string keys;
    for (const auto& [key, value] : mr.json().items()) keys += (keys.empty() ? "" : ", ") + key;
    mr.fail_here("give one motion: \"translate\", \"rotate\", \"oscillate\" or \"table\" (got " +
                 (keys.empty() ? std::string("none") : keys) + ")");
  }
  WallMotion m;
  auto start_end = [&](JsonReader& r) {
    m.start = r.number("start", 0, -1e12, 1e12);
    m.end = r.number("end", HUGE_VAL, -1e12, 1e12);
    if (!(m.end >= m.start)) r.fail("end", "must not be before start (" + std::to_string(m.start) + " s)");
  };
  if (mr.has("translate")) {
    m.kind = MotionKind::Translate;
    auto r = mr.child("translate");
    const auto v = r.required_vector("velocity", Dim);
    for (std::size_t a = 0; a < Dim; ++a) m.velocity[a] = v[a];
    start_end(r);
    r.finish();
  } else if (mr.has("rotate")) {
    m.kind = MotionKind::Rotate;
    auto r = mr.child("rotate");
    if (Dim == 3)
      read_unit(r, "axis", 3, m.axis);
    else if (r.has("axis"))
      r.fail("axis",
             "in 2D the rotation is about the out-of-plane axis (positive omega turns x towards y); "
             "leave \"axis\" out");
    const auto c = r.required_vector("center", Dim);
    for (std::size_t a = 0; a < Dim; ++a) m.center[a] = c[a];
    m.omega = r.required_number("omega", -1e6, 1e6);
    start_end(r);
    r.finish();
  } else if (mr.has("oscillate")) {
    m.kind = MotionKind::Oscillate;
    auto r = mr.child("oscillate");
    read_unit(r, "direction", Dim, m.direction);
    m.amplitude = r.required_number("amplitude", -1e9, 1e9);
    if (!(m.amplitude >= 0)) r.fail("amplitude", "must be >= 0 (got " + std::to_string(m.amplitude) + ")");
    m.period = r.required_number("period", -1e12, 1e12);
    if (!(m.period > 0)) r.fail("period", "must be > 0 s (got " + std::to_string(m.period) + ")");
    r.finish();
  } else {
    m.kind = MotionKind::Table;
    const std::string name = mr.string("table", "");
    const std::string text = read_motion_table_file(mr, name, files);
    m.table_begin = static_cast<std::uint32_t>(cfg.wall_motion.rows.size());
    try {
      parse_motion_table(text, name, Dim, cfg.wall_motion.rows);
    } catch (const InputError& err) {
      mr.fail("table", err.what());
    }
    m.table_end = static_cast<std::uint32_t>(cfg.wall_motion.rows.size());
    // The angle column turns about this axis through `center` (moved with the displacement).
    if (Dim == 3 && mr.has("axis")) read_unit(mr, "axis", 3, m.axis);
    const auto c = mr.vector("center", Dim, std::vector<double>(Dim, 0.0));
    for (std::size_t a = 0; a < Dim; ++a) m.center[a] = c[a];
  }
  mr.finish();
  cfg.wall_motion.motions.push_back(m);
  return static_cast<std::int32_t>(cfg.wall_motion.motions.size() - 1);
}

#define CELLSPH_MOTION_INSTANTIATE(D, R) \
  template std::int32_t read_motion<D, R>(JsonReader&, const MeshFiles&, SolverConfig<D, R>&);
CELLSPH_MOTION_INSTANTIATE(2, float)
CELLSPH_MOTION_INSTANTIATE(2, double)
CELLSPH_MOTION_INSTANTIATE(3, float)
CELLSPH_MOTION_INSTANTIATE(3, double)
#undef CELLSPH_MOTION_INSTANTIATE

}  // namespace cellsph::scene_detail
