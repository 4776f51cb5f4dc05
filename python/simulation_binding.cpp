// cellsph.Scene and cellsph.Simulation: the library's scenes (scene/scene.hpp), Simulation
// (solver/simulation.hpp), frame writers (io/frame_output.hpp) and checkpoints
// (io/simulation_checkpoint.hpp) for Python. Scenes are templated on dimension and precision; the choice
// is made here, once, from the scene's header (SimImpl<Dim, Real> behind the SimBase interface).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/field_types.hpp"
#include "cellsph/io/frame_output.hpp"
#include "cellsph/io/frames_index.hpp"
#include "cellsph/io/simulation_checkpoint.hpp"
#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph::python {
namespace {

namespace fs = std::filesystem;

// The caller data of the checkpoints written by Simulation.checkpoint(): this magic, then the scene as JSON.
constexpr char kPyMagic[8] = {'C', 'S', 'P', 'H', 'P', 'Y', '0', '1'};

// A path argument: str or os.PathLike.
fs::path path_arg(const py::handle& p, const char* name) {
  try {
    return fs::path(py::module_::import("os").attr("fspath")(p).cast<std::string>());
  } catch (const py::error_already_set&) {
    throw ArgumentError(std::string(name) + ": expected a str or os.PathLike, got " + repr_text(p));
  } catch (const py::cast_error&) {
    throw ArgumentError(std::string(name) + ": expected a str path, got " + repr_text(p));
  }
}

// A Python object as JSON (through the json module: dicts, lists, str, numbers, bools, None).
nlohmann::json to_json(const py::handle& obj, const std::string& what) {
  std::string text;
  try {
    text = py::module_::import("json").attr("dumps")(obj, py::arg("allow_nan") = false).cast<std::string>();
  } catch (const py::error_already_set& e) {
    throw ArgumentError(what + ": not expressible as JSON (" + std::string(e.what()) +
                        "): " + repr_text(obj));
  }
  return nlohmann::json::parse(text);
}

py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// ---------------------------------------------------------------------------------------------------
// Scene: the JSON of a scene (as `cellsph run` reads it) and what validating it found.

struct PyScene {
  nlohmann::json json;
  std::string source;
  SceneHeader header;
  OutputSettings output;
  std::size_t particles = 0;

  PyScene(nlohmann::json j, std::string src) : json(std::move(j)), source(std::move(src)) { validate(); }

  // Everything `cellsph run` checks before it runs (the same messages): the header, then every key.
  void validate() {
    header = read_scene_header(json, source);
    auto take = [&](const auto& s) {
      output = s.output;
      particles = s.particles.size();
    };
    if (header.dim == 2)
      header.single_precision ? take(load_scene<2, float>(json, source))
                              : take(load_scene<2, double>(json, source));
    else
      header.single_precision ? take(load_scene<3, float>(json, source))
                              : take(load_scene<3, double>(json, source));
  }

  static PyScene load(const py::handle& name_or_path) {
    std::string source;
    std::string arg = py::isinstance<py::str>(name_or_path) ? name_or_path.cast<std::string>()
                                                            : path_arg(name_or_path, "name_or_path").string();
    nlohmann::json j = read_scene_json(arg, source);
    return PyScene(std::move(j), std::move(source));
  }

  static PyScene from_dict(const py::handle& d, const std::string& source) {
    if (!py::isinstance<py::dict>(d)) throw ArgumentError("scene: expected a dict, got " + repr_text(d));
    return PyScene(to_json(d, source), source);
  }

  // scene.set("/json/pointer", value): the edit of `cellsph run --set`, then the whole scene validated.
  void set(const std::string& pointer, const py::handle& value) {
    if (pointer.empty() || pointer[0] != '/' || pointer.find('=') != std::string::npos)
      throw ArgumentError("pointer: '" + pointer + "' is not a JSON pointer like /phases/0/viscosity");
    nlohmann::json edited = json;
    std::string src = source;
    try {
      apply_scene_edits(edited, {pointer + "=" + to_json(value, "value").dump()}, src);
    } catch (const InputError& e) {
      std::string msg = e.what();
      if (msg.rfind("--set ", 0) == 0) msg = "set: " + msg.substr(6);
      throw ArgumentError(msg);
    }
    PyScene checked(std::move(edited), std::move(src));  // throws (and leaves *this as it was) if invalid
    *this = std::move(checked);
  }

  [[nodiscard]] std::string precision() const { return header.single_precision ? "float" : "double"; }
};

// ---------------------------------------------------------------------------------------------------
// Simulation

constexpr double kTimeTolerance = 1e-12;  // as `cellsph run`: a time t counts as reached at t (1 - 1e-12)

class SimBase {
 public:
  explicit SimBase(PyScene scene, int threads) : scene_(std::move(scene)), threads_(threads) {}
  virtual ~SimBase() = default;
  SimBase(const SimBase&) = delete;
  SimBase& operator=(const SimBase&) = delete;

  virtual void step() = 0;
  [[nodiscard]] virtual double time() const = 0;
  [[nodiscard]] virtual std::uint64_t steps() const = 0;
  [[nodiscard]] virtual std::uint64_t wall_corrections() const = 0;
  [[nodiscard]] virtual double last_dt() const = 0;
  [[nodiscard]] virtual std::size_t size() const = 0;
  [[nodiscard]] virtual std::size_t fluid_count() const = 0;
  // Copies of the fields in id order; all of them (library names) or one.
  [[nodiscard]] virtual py::dict fields() const = 0;
  [[nodiscard]] virtual py::array field(std::string_view name) const = 0;
  virtual py::list write_frame(const fs::path& dir, const OutputFormats& formats) = 0;
  virtual void checkpoint(const fs::path& path) const = 0;
  virtual void restore(const fs::path& path) = 0;
  [[nodiscard]] virtual py::dict timings() const = 0;
  [[nodiscard]] virtual py::object solver_stats() const = 0;
  virtual void use_backend(Backend b) = 0;

  [[nodiscard]] const PyScene& scene() const { return scene_; }
  [[nodiscard]] int threads() const { return threads_; }
  std::mutex& mutex() { return mutex_; }

 protected:
  // The checkpoint's caller data: our magic and the scene, so resume() can rebuild the simulation.
  [[nodiscard]] std::string extra() const {
    nlohmann::json j;
    j["scene"] = scene_.json;
    j["source"] = scene_.source;
    return std::string(kPyMagic, sizeof kPyMagic) + j.dump();
  }

  PyScene scene_;
  int threads_;
  // One call at a time into the solver: step() and checkpoint() run without the GIL. Rule: the mutex is
  // taken after releasing the GIL or with it held, and never held while waiting for the GIL.
  std::mutex mutex_;
};

template <int Dim, class Real>
class SimImpl final : public SimBase {
 public:
  SimImpl(PyScene scene, int threads) : SimBase(std::move(scene), threads), sim_(make(scene_)) {}

  void step() override { sim_.step(); }
  void use_backend(Backend b) override { sim_.use_backend(b); }
  [[nodiscard]] double time() const override { return double(sim_.time()); }
  [[nodiscard]] std::uint64_t steps() const override { return sim_.steps(); }
  [[nodiscard]] std::uint64_t wall_corrections() const override { return sim_.wall_corrections(); }
  [[nodiscard]] double last_dt() const override { return double(sim_.last_dt()); }
  [[nodiscard]] std::size_t size() const override { return sim_.particles().size(); }
  [[nodiscard]] std::size_t fluid_count() const override { return sim_.fluid_count(); }

  [[nodiscard]] py::dict fields() const override {
    const auto from = id_order();
    py::dict d;
    sim_.particles().for_each_field(
        [&](std::string_view name, const auto& f) { d[py::str(std::string(name))] = gather(f, from); });
    return d;
  }

  [[nodiscard]] py::array field(std::string_view wanted) const override {
    const auto from = id_order();
    py::array out;
    sim_.particles().for_each_field([&](std::string_view name, const auto& f) {
      if (name == wanted) out = gather(f, from);
    });
    CELLSPH_CHECK(out, "no particle field '" << wanted << "'");
    return out;
  }

  py::list write_frame(const fs::path& dir, const OutputFormats& formats) override {
    auto key = dir.lexically_normal().string();
    auto it = outputs_.find(key);
    if (it == outputs_.end() || it->second.formats != formats.names()) {
      Out o{std::make_unique<FrameOutput<Dim, Real>>(dir, formats, fluid_filter()), formats.names(), 0};
      // A folder with frames already (an earlier run, a resumed simulation): continue its numbering.
      const auto index = dir / "frames.csv";
      if (fs::exists(index)) {
        const FramesIndex old = read_frames_index(index);
        if (!old.rows().empty()) o.next = old.rows().back().frame + 1;
        o.frames->resume(o.next);
      }
      it = outputs_.insert_or_assign(key, std::move(o)).first;
    }
    // With the GIL held: the caller holds the mutex, and no thread may wait for the GIL holding it.
    ScopedThreads scoped(threads_);
    const std::vector<fs::path> files = it->second.frames->write(sim_.particles(), it->second.next, time());
    ++it->second.next;
    py::list written;
    for (const auto& f : files) written.append(py::str(f.string()));
    return written;
  }

  void checkpoint(const fs::path& path) const override { write_simulation_checkpoint(sim_, extra(), path); }
  void restore(const fs::path& path) override { read_simulation_checkpoint(path, sim_); }

  [[nodiscard]] py::dict timings() const override {
    const StepTimings& t = sim_.timings();
    py::dict d;
    d["neighbors_ms"] = t.neighbors;
    d["forces_ms"] = t.forces;
    d["integration_ms"] = t.integration;
    d["reorder_ms"] = t.reorder;
    d["list_builds"] = t.list_builds;
    return d;
  }

  // The implicit solves of DFSPH and IISPH (models/dfsph.hpp's DfsphStats), as `cellsph run`'s summary
  // shows them; None for the explicit models.
  [[nodiscard]] py::object solver_stats() const override {
    const DfsphStats* stats = sim_.solver_stats();
    if (stats == nullptr) return py::none();
    const DfsphStats& st = *stats;
    py::dict d;
    d["steps"] = st.steps;
    d["density_iterations"] = st.density_iterations;
    d["divergence_iterations"] = st.divergence_iterations;
    d["last_density_iterations"] = st.last_density_iterations;
    d["last_divergence_iterations"] = st.last_divergence_iterations;
    d["last_density_error_percent"] = st.last_density_error;
    d["last_divergence_error_percent"] = st.last_divergence_error;
    d["max_density_error_percent"] = st.max_density_error;
    d["max_iteration_hits"] = st.max_iteration_hits;
    if (st.max_iteration_hits > 0) {
      py::dict hit;
      hit["step"] = st.last_hit_step;
      hit["solve"] = std::string(st.last_hit_solve);
      hit["iterations"] = st.last_hit_iterations;
      hit["error_percent"] = st.last_hit_error;
      hit["bound_percent"] = st.last_hit_bound;
      d["last_max_iteration_hit"] = hit;
    } else {
      d["last_max_iteration_hit"] = py::none();
    }
    return d;
  }

 private:
  struct Out {
    std::unique_ptr<FrameOutput<Dim, Real>> frames;
    std::vector<std::string> formats;
    std::size_t next = 0;
  };

  static Simulation<Dim, Real> make(const PyScene& s) {
    Scene<Dim, Real> scene = load_scene<Dim, Real>(s.json, s.source);
    return Simulation<Dim, Real>(scene.solver, std::move(scene.particles));
  }

  // CSV frames hold the fluid particles only, as `cellsph run` writes them.
  CsvRowFilter fluid_filter() const {
    return [this](std::size_t i) {
      return sim_.particles().kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid);
    };
  }

  // from[k]: the index of the particle with the k-th smallest id (the one with id k unless emitters and
  // sinks have changed the count: then the ids have gaps).
  [[nodiscard]] std::vector<std::uint32_t> id_order() const {
    const auto& id = sim_.particles().id;
    std::vector<std::uint32_t> from(id.size());
    for (std::size_t s = 0; s < id.size(); ++s) from[s] = static_cast<std::uint32_t>(s);
    std::sort(from.begin(), from.end(), [&id](std::uint32_t a, std::uint32_t b) { return id[a] < id[b]; });
    return from;
  }

  template <class Field>
  static py::array gather(const Field& f, const std::vector<std::uint32_t>& from) {
    using FT = io::FieldOf<Field>;
    using S = typename FT::Scalar;
    constexpr int C = FT::components;
    const auto n = static_cast<py::ssize_t>(from.size());
    py::array_t<S> out(C == 1 ? std::vector<py::ssize_t>{n} : std::vector<py::ssize_t>{n, py::ssize_t{C}});
    S* o = out.mutable_data();
    for (std::size_t k = 0; k < from.size(); ++k)
      for (int c = 0; c < C; ++c) o[k * C + static_cast<std::size_t>(c)] = FT::get(f[from[k]], c);
    return out;
  }

  Simulation<Dim, Real> sim_;
  std::map<std::string, Out> outputs_;
};

std::unique_ptr<SimBase> make_sim(PyScene scene, int threads) {
  ScopedThreads scoped(threads);
  const SceneHeader h = scene.header;
  if (h.dim == 2) {
    if (h.single_precision) return std::make_unique<SimImpl<2, float>>(std::move(scene), threads);
    return std::make_unique<SimImpl<2, double>>(std::move(scene), threads);
  }
  if (h.single_precision) return std::make_unique<SimImpl<3, float>>(std::move(scene), threads);
  return std::make_unique<SimImpl<3, double>>(std::move(scene), threads);
}

// The backend named by `backend` (ValueError if unknown); RuntimeError when this build or machine cannot
// run it (no CUDA backend in the build, or no usable device: the CUDA runtime's message).
Backend check_backend(const std::string& backend) {
  const auto b = parse_backend(backend);
  if (!b) throw ArgumentError("backend: unknown backend '" + backend + "' (expected 'cpu' or 'cuda')");
  try {
    require_backend(*b, "backend '" + backend + "'");
  } catch (const InputError& e) {
    throw std::runtime_error(e.what());
  }
  return *b;
}

class PySimulation {
 public:
  PySimulation(const PyScene& scene, int threads, const std::string& backend) {
    const Backend b = check_backend(backend);
    sim_ = make_sim(scene, check_threads(threads));
    if (b != Backend::Cpu) sim_->use_backend(b);
  }

  static PySimulation resume(const py::handle& path_obj, int threads, const std::string& backend) {
    const Backend b = check_backend(backend);
    check_threads(threads);
    const fs::path path = path_arg(path_obj, "path");
    const std::string extra = read_simulation_checkpoint_extra(path);
    if (extra.size() < sizeof kPyMagic || std::memcmp(extra.data(), kPyMagic, sizeof kPyMagic) != 0)
      throw ArgumentError("checkpoint '" + path.string() +
                          "': not written by cellsph.Simulation.checkpoint() (a `cellsph run` folder "
                          "continues with `cellsph run --resume DIR`)");
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(extra.substr(sizeof kPyMagic));
      PyScene scene(j.at("scene"), j.at("source").get<std::string>());
      PySimulation s(std::move(scene), threads);
      ScopedThreads scoped(threads);
      s.sim_->restore(path);
      if (b != Backend::Cpu) s.sim_->use_backend(b);  // a checkpoint does not depend on the backend
      return s;
    } catch (const nlohmann::json::exception& e) {
      throw ArgumentError("checkpoint '" + path.string() + "': its scene is damaged (" + e.what() + ")");
    }
  }

  void step(long count) {
    if (count < 0) throw ArgumentError("count: must be >= 0, got " + std::to_string(count));
    for (long k = 0; k < count; ++k) {
      {
        py::gil_scoped_release nogil;
        std::lock_guard lock(sim_->mutex());
        ScopedThreads scoped(sim_->threads());
        sim_->step();
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  // Steps until time >= t (as `cellsph run --until t`: the last step is not shortened). callback(sim)
  // after every step; returning False stops early.
  void run_until(py::object self, double t, const py::object& callback) {
    if (!std::isfinite(t)) throw ArgumentError("t: must be a finite time, got " + std::to_string(t));
    while (!(sim_->time() >= t * (1 - kTimeTolerance))) {
      step(1);
      if (!callback.is_none()) {
        py::object r = callback(self);
        if (r.is(py::bool_(false))) break;
      }
    }
  }

  py::list write_frame(const py::handle& dir, const py::object& formats) {
    const fs::path d = path_arg(dir, "dir");
    std::string list;
    auto add = [&list](const std::string& f) {
      if (!list.empty()) list.push_back(',');
      list.append(f);
    };
    if (formats.is_none()) {
      for (const auto& f : sim_->scene().output.formats) add(f);
    } else if (py::isinstance<py::str>(formats)) {
      list = formats.cast<std::string>();
    } else {
      for (const auto& f : formats) add(py::str(f).cast<std::string>());
    }
    const OutputFormats fmts = parse_output_formats(list, "formats");
    std::lock_guard lock(sim_->mutex());
    return sim_->write_frame(d, fmts);
  }

  void checkpoint(const py::handle& path) {
    const fs::path p = path_arg(path, "path");
    py::gil_scoped_release nogil;
    std::lock_guard lock(sim_->mutex());
    sim_->checkpoint(p);
  }

  template <class F>
  auto locked(F&& f) const {
    std::lock_guard lock(sim_->mutex());
    return f(*sim_);
  }

  SimBase& impl() const { return *sim_; }

 private:
  PySimulation(PyScene scene, int threads) : sim_(make_sim(std::move(scene), threads)) {}
  std::unique_ptr<SimBase> sim_;
};

// Scene and scenes().
void register_scene(py::module_& m) {
  using namespace pybind11::literals;

  py::class_<PyScene>(m, "Scene",
                      R"doc(A scene: the JSON of docs/scenes.md, validated as `cellsph run` validates it.

    scene = cellsph.Scene.load("dam-break-2d")      # a built-in scene name or a .json path
    scene.set("/spacing", 0.04)                     # as `cellsph run --set /spacing=0.04`
    scene = cellsph.Scene.from_dict(d)              # a scene as a Python dict

Every error is a ValueError with the message of the command line (file or source, key path, value).)doc")
      .def_static("load", &PyScene::load, "A built-in scene (see scenes()) or a scene .json file.",
                  "name_or_path"_a)
      .def_static("from_dict", &PyScene::from_dict,
                  "A scene from its JSON as a dict; `source` labels it in error messages.", "scene"_a,
                  "source"_a = "Scene.from_dict")
      .def(
          "set",
          [](PyScene& s, const std::string& pointer, const py::object& value) -> PyScene& {
            s.set(pointer, value);
            return s;
          },
          py::return_value_policy::reference_internal,
          "Sets the value at a JSON pointer (e.g. '/phases/0/viscosity'), then validates the scene; on error "
          "(ValueError) the scene is unchanged. Returns the scene.",
          "pointer"_a, "value"_a)
      .def(
          "to_dict", [](const PyScene& s) { return to_python(s.json); }, "The scene's JSON as a new dict.")
      .def_property_readonly(
          "name", [](const PyScene& s) { return s.header.name; }, "The scene's name.")
      .def_property_readonly(
          "description", [](const PyScene& s) { return s.header.description; }, "One line.")
      .def_property_readonly(
          "dim", [](const PyScene& s) { return s.header.dim; }, "2 or 3.")
      .def_property_readonly("precision", &PyScene::precision, "'float' or 'double'.")
      .def_property_readonly(
          "source", [](const PyScene& s) { return s.source; },
          "Where the scene came from (file, built-in name, edits), as messages name it.")
      .def_property_readonly(
          "end_time", [](const PyScene& s) { return s.output.end_time; }, "time.end [s].")
      .def_property_readonly(
          "fps", [](const PyScene& s) { return s.output.fps; }, "output.fps.")
      .def_property_readonly(
          "formats", [](const PyScene& s) { return s.output.formats; }, "output.formats.")
      .def_property_readonly(
          "particle_count", [](const PyScene& s) { return s.particles; },
          "Particles (fluid and boundary) the scene makes.")
      .def("__repr__", [](const PyScene& s) {
        return "<cellsph.Scene '" + s.header.name + "': " + std::to_string(s.header.dim) + "D " +
               s.precision() + ", " + std::to_string(s.particles) + " particles, from " + s.source + ">";
      });

  m.def(
      "scenes",
      [] {
        py::list l;
        for (const auto& s : builtin_scenes()) l.append(std::string(s.name));
        return l;
      },
      "The names of the built-in scenes.");
}

// Simulation's constructors, its stepping and its outputs.
void def_simulation_steps(py::class_<PySimulation>& c) {
  using namespace pybind11::literals;
  c.def(py::init<const PyScene&, int, const std::string&>(), "scene"_a, "threads"_a = 0, "backend"_a = "cpu",
        "threads: OpenMP threads for every call (0 = all cores). backend: 'cpu' or 'cuda' (RuntimeError "
        "when this build has no CUDA backend or finds no usable device; docs/gpu.md).")
      .def_static("resume", &PySimulation::resume, "A simulation from a file written by checkpoint().",
                  "path"_a, "threads"_a = 0, "backend"_a = "cpu")
      .def("step", &PySimulation::step, "Advances `count` time steps.", "count"_a = 1)
      .def(
          "run_until",
          [](py::object self, double t, const py::object& callback) {
            self.cast<PySimulation&>().run_until(self, t, callback);
          },
          "Steps until time >= t (the last step is not shortened), as `cellsph run --until t`. callback(sim) "
          "runs after every step; returning False stops early.",
          "t"_a, "callback"_a = py::none())
      .def("write_frame", &PySimulation::write_frame,
           "Writes the current state as the next frame of folder `dir` (frame_NNNNN.vtu/.ply/.csv, "
           "frames.csv, "
           "particles.pvd; created if needed; numbering continues a frames.csv already there). formats: "
           "'vtu,csv', a list, or None for the scene's output.formats. Returns the files written.",
           "dir"_a, "formats"_a = py::none())
      .def("checkpoint", &PySimulation::checkpoint,
           "Writes the whole state (every particle field, the integrator state and the scene) to `path`, "
           "atomically; Simulation.resume(path) continues bit for bit.",
           "path"_a);
}

// Simulation's clock, thread count, scene and particle counts.
void def_simulation_state(py::class_<PySimulation>& c) {
  c.def_property_readonly(
       "time", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.time(); }); },
       "Simulated time [s].")
      .def_property_readonly(
          "steps", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.steps(); }); },
          "Steps taken.")
      .def_property_readonly(
          "wall_corrections",
          [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.wall_corrections(); }); },
          "Fluid particles put back out of a wall or obstacle they would have ended a step inside, since "
          "this Simulation was made (docs/physics.md, \"Walls that hold every particle\").")
      .def_property_readonly(
          "dt", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.last_dt(); }); },
          "The last step's dt [s].")
      .def_property_readonly(
          "threads", [](const PySimulation& s) { return s.impl().threads(); },
          "OpenMP threads of every call (0 = all cores).")
      .def_property_readonly(
          "scene", [](const PySimulation& s) { return s.impl().scene(); }, "A copy of the scene.")
      .def_property_readonly(
          "dim", [](const PySimulation& s) { return s.impl().scene().header.dim; }, "2 or 3.")
      .def_property_readonly(
          "size", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.size(); }); },
          "Particles, fluid and boundary.")
      .def_property_readonly(
          "fluid_count",
          [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.fluid_count(); }); },
          "Fluid particles (kind 0).");
}

// Simulation's particle fields (copies in id order), timings and solver statistics.
void def_simulation_fields(py::class_<PySimulation>& c) {
  auto field_prop = [](const char* name) {
    return [name](const PySimulation& s) { return s.locked([&](SimBase& b) { return b.field(name); }); };
  };
  c.def_property_readonly("positions", field_prop("position"), "(n, dim) positions [m], copy in id order.")
      .def_property_readonly(
          "velocities", field_prop("velocity"),
          "(n, dim) velocities [m/s], copy in id order (the paper model holds v(t - dt/2)).")
      .def_property_readonly("density", field_prop("density"), "(n,) density [kg/m^3], copy in id order.")
      .def_property_readonly("pressure", field_prop("pressure"), "(n,) pressure [Pa], copy in id order.")
      .def_property_readonly("phase", field_prop("phase"), "(n,) int32 phase index, copy in id order.")
      .def_property_readonly("kind", field_prop("kind"), "(n,) uint8: 0 fluid, 1 boundary; copy in id order.")
      .def_property_readonly("id", field_prop("id"),
                             "(n,) uint32 ids: 0..n-1, since every field is in id order.")
      .def(
          "fields", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.fields(); }); },
          "Every particle field (the library's field list: position, velocity, force, mass, density, "
          "pressure, "
          "support, color, viscosity, phase, level, tick, kind, id) as copies in id order.")
      .def_property_readonly(
          "timings", [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.timings(); }); },
          "Wall-clock time per phase of all steps so far [ms].")
      .def_property_readonly(
          "solver_stats",
          [](const PySimulation& s) { return s.locked([](SimBase& b) { return b.solver_stats(); }); },
          "The implicit pressure solves (solver.model 'dfsph' or 'iisph') since this object was made: steps, "
          "iterations summed (density_iterations, divergence_iterations; IISPH's in density_iterations) and "
          "of the last step, the average density error of the last step and the largest [% of rest density], "
          "the last divergence error [% per step], and the solves stopped at max_iterations above their "
          "bound "
          "(max_iteration_hits; last_max_iteration_hit: its step, solve, iterations, error_percent, "
          "bound_percent, or None). None for the explicit models.");
}

}  // namespace

void register_simulation(py::module_& m) {
  register_scene(m);
  py::class_<PySimulation> c(m, "Simulation",
                             R"doc(A running simulation of a Scene (the solver of `cellsph run`).

    sim = cellsph.Simulation(scene, threads=2)
    sim.run_until(0.5)                  # steps as `cellsph run --until 0.5`
    x = sim.positions                   # (n, dim) copy, in id order

The same scene and thread count give the same bits as `cellsph run`. Particle fields are copies in id order
(row k is the particle with id k, for every field and every call), fluid and boundary particles together
(`kind`: 0 fluid, 1 boundary). The GIL is released while the solver steps.)doc");
  def_simulation_steps(c);
  def_simulation_state(c);
  def_simulation_fields(c);
}

}  // namespace cellsph::python
