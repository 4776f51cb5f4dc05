// `cellsph run [SCENE]` and `cellsph scenes`: run a scene from the command line, writing frames that
// ParaView (VTU + PVD), Blender (PLY) and scripts (CSV, frames.csv) open, optional PNG pictures and an
// MP4, checkpoints, and a resume that continues bit for bit. A run checks and builds everything before
// its first write (a failed start leaves the output location as it was), and stops cleanly on SIGINT or
// SIGTERM (a checkpoint, then exit 130 or 143).
#include <signal.h>
#include <sys/types.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/core/format.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/distributed/communicator.hpp"
#include "cellsph/io/frame_output.hpp"
#include "cellsph/io/simulation_checkpoint.hpp"
#include "cellsph/probes/probe_log.hpp"
#include "cellsph/probes/probes.hpp"
#include "cellsph/render/renderer.hpp"
#include "cellsph/render/video.hpp"
#include "cellsph/scene/json_reader.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/compressibility_watch.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/surface/surface.hpp"
#include "commands.hpp"
#include "progress.hpp"

namespace cellsph::app {
namespace {

// Creates an output folder (and its parents); a folder that cannot be made is the user's to fix
// (a read-only place, a file in the way), so it is an InputError naming it and the reason.
void make_folder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("output folder '" + dir.string() + "': cannot be created: " + ec.message());
}

constexpr const char* kDefaultScene = "dam-break-2d";
constexpr const char* kRunFile = "run.json";
constexpr const char* kCheckpointFile = "checkpoint.bin";
// The checkpoint (io/simulation_checkpoint.hpp) carries the loop state below as its caller data:
// kLoopStateVersion, then the next frame number (u32 + u64, native = little endian).
constexpr std::uint32_t kLoopStateVersion = 1;
// The magic of the checkpoints of earlier builds (their own format, before io/checkpoint was used).
constexpr char kOldRunMagic[8] = {'C', 'S', 'P', 'H', 'R', 'U', 'N', '1'};

struct RunOptions {
  std::string scene;
  std::string out;
  int threads = 0;
  std::string method;
  std::string backend;  // empty: the scene's solver.backend
  double until = -1;
  long steps = -1;
  double fps = -1;
  std::string formats;
  bool render = false;
  std::string color_by;
  bool surface = false;
  std::string surface_format = "ply";
  bool quiet = false;
  std::string resume;
  std::vector<std::string> sets;  // --set /json/pointer=value edits of the scene
};

// The state of the run loop that a checkpoint stores besides the simulation.
struct LoopState {
  std::uint64_t next_frame = 0;

  [[nodiscard]] std::string encode() const {
    std::string s(sizeof kLoopStateVersion + sizeof next_frame, '\0');
    std::memcpy(s.data(), &kLoopStateVersion, sizeof kLoopStateVersion);
    std::memcpy(s.data() + sizeof kLoopStateVersion, &next_frame, sizeof next_frame);
    return s;
  }
  void decode(const std::string& s, const std::filesystem::path& file) {
    std::uint32_t version = 0;
    if (s.size() == sizeof version + sizeof next_frame) std::memcpy(&version, s.data(), sizeof version);
    if (version != kLoopStateVersion)
      throw InputError("checkpoint '" + file.string() + "': run loop state of " + std::to_string(s.size()) +
                       " bytes, version " + std::to_string(version) + " (this cellsph reads version " +
                       std::to_string(kLoopStateVersion) + ", " +
                       std::to_string(sizeof version + sizeof next_frame) + " bytes)");
    std::memcpy(&next_frame, s.data() + sizeof version, sizeof next_frame);
  }
};

// Earlier builds wrote checkpoint.bin in a format of their own: say so rather than "bad magic".
void reject_old_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[sizeof kOldRunMagic] = {};
  in.read(magic, sizeof magic);
  if (in && std::memcmp(magic, kOldRunMagic, sizeof magic) == 0)
    throw InputError("checkpoint '" + file.string() +
                     "': written by an earlier cellsph in a format this one does not read (CSPHRUN1); "
                     "run the scene again");
}

// How many solves stopped at max_iterations get a warning line of their own; later ones are counted on the
// progress line and in the summary, so that a run that keeps hitting the limit does not flood its log.
constexpr std::uint64_t kMaxIterationWarnings = 10;

// A warning line for each implicit solve that a step left above its bound at max_iterations
// (models/dfsph.hpp's implicit_check_solve), up to kMaxIterationWarnings in a run. `seen` is the count of
// such solves already reported on.
template <int Dim, class Real>
void warn_max_iterations(const Simulation<Dim, Real>& sim, Progress& progress, std::uint64_t& seen) {
  const DfsphStats* stats = sim.solver_stats();
  if (stats == nullptr) return;
  const DfsphStats& st = *stats;
  const std::uint64_t before = seen;
  seen = st.max_iteration_hits;
  if (seen == before || before >= kMaxIterationWarnings) return;
  const std::uint64_t others = seen - before - 1;
  const std::string more = others == 0   ? ""
                           : others == 1 ? " (and one more solve of this step)"
                                         : " (and " + std::to_string(others) + " more solves of this step)";
  std::string unit = st.last_hit_unit;  // "sweeps" -> "1 sweep"
  if (st.last_hit_iterations == 1) unit.pop_back();
  progress.finish();
  std::fprintf(
      stderr,
      "cellsph: warning: step %llu (t = %.6g s): the %s solve stopped at max_iterations (%d %s) with "
      "average error %.3g%%, above its bound %.3g%%%s%s\n",
      static_cast<unsigned long long>(st.last_hit_step), double(sim.time()), st.last_hit_solve,
      st.last_hit_iterations, unit.c_str(), st.last_hit_error, st.last_hit_bound, more.c_str(),
      seen >= kMaxIterationWarnings
          ? "; further ones are counted on the progress line and in the summary, not logged"
          : "");
}

// The compressibility warnings (solver/compressibility_watch.hpp) that the particles call for, looked at
// when a frame has been written: on a line of their own, each once.
template <int Dim, class Real>
void warn_compressibility(const Simulation<Dim, Real>& sim, Progress& progress,
                          CompressibilityWatch<Dim, Real>& watch) {
  for (const std::string& w : watch.check(sim.config(), sim.particles(), double(sim.time()))) {
    progress.finish();
    std::fprintf(stderr, "cellsph: warning: %s\n", w.c_str());
  }
}

// The share of the fluid per simulated second that the solid guard may put back before the summary warns.
constexpr double kWallCorrectionWarning = 0.001;

// ---- Stopping on SIGINT / SIGTERM ------------------------------------------------------------------
// The handler only records the signal (async-signal-safe); the run loop looks at it between steps,
// writes a checkpoint and returns 128 + the signal. SA_RESETHAND: a second Ctrl-C kills at once.
volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int sig) {
  g_stop_signal = sig;
}

// Whether to stop before the next step: a signal to any rank stops every rank after the same step
// (mpirun passes SIGINT and SIGTERM to each rank, which may see it a step apart). Returns the signal.
int stop_signal(bool across_ranks) {
  if (!across_ranks) return g_stop_signal;
  return static_cast<int>(distributed::world().max(double(g_stop_signal)));
}

void install_stop_handlers() {
  g_stop_signal = 0;
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND | SA_RESTART;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
}

const char* signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "a signal";
}

// A word the shell reads back unchanged.
std::string shell_word(const std::string& s) {
  const bool plain = !s.empty() && s.find_first_not_of(
                                       "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                       "0123456789_./+-=:,@%") == std::string::npos;
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return {buf, r.ptr};
}

// The command that continues this run: the folder, plus what this invocation set that run.json does not
// keep (the thread count, and the overrides given to a --resume).
std::string resume_command(const RunOptions& given, const std::filesystem::path& out) {
  // Across ranks: the same launcher line (any rank count resumes it; docs/distributed.md).
  const int ranks = distributed::world().size();
  std::string c = ranks > 1 ? "mpirun -np " + std::to_string(ranks) + " " : "";
  c += shell_word(program_name()) + " run --resume " + shell_word(out.string());
  if (given.threads > 0) c += " --threads " + std::to_string(given.threads);
  if (!given.resume.empty()) {
    if (given.until > 0) c += " --until " + shortest(given.until);
    if (given.steps >= 0) c += " --steps " + std::to_string(given.steps);
    if (given.fps > 0) c += " --fps " + shortest(given.fps);
    if (!given.method.empty()) c += " --method " + shell_word(given.method);
    if (!given.formats.empty()) c += " --format " + shell_word(given.formats);
    if (given.render) c += " --render";
    if (!given.color_by.empty()) c += " --color-by " + shell_word(given.color_by);
    if (given.surface) c += " --surface";
  }
  return c;
}

// Removes the temporary files of killed writers (AtomicFile names; never those of a live process).
void remove_stale_temporaries(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  std::vector<std::filesystem::path> stale;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!is_atomic_temp_name(name)) continue;
    const auto tmp = name.rfind(".tmp");
    const long pid = std::strtol(name.c_str() + tmp + 4, nullptr, 10);
    if (pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM)) continue;  // alive
    stale.push_back(e.path());
  }
  for (const auto& p : stale) std::filesystem::remove(p, ec);
}

// The run's output settings: the scene's output section with the command line's end time, frame rate,
// frame formats and picture colours over it, and the picture and surface options that follow.
struct RunOutputSettings {
  OutputSettings os;
  OutputFormats formats;
  RenderOptions ropt;
  SurfaceOptions sopt;
};

// --method and --backend over the scene's solver section. Without --backend the scene's own backend is
// checked here, before anything is written.
template <int Dim, class Real>
void apply_solver_options(SolverConfig<Dim, Real>& cfg, const RunOptions& opt, const std::string& source) {
  if (!opt.method.empty()) {
    auto m = parse_method(opt.method);
    if (!m)
      throw InputError("--method: unknown method '" + opt.method + "' (expected " + method_names_joined() +
                       ")");
    cfg.search.method = *m;
  }
  if (!opt.backend.empty())
    cfg.backend = *parse_backend(opt.backend);  // checked by run_command
  else
    require_backend(cfg.backend, source + ": /solver/backend");  // the scene's, before anything is written
}

RunOutputSettings output_settings(OutputSettings os, const RunOptions& opt) {
  RunOutputSettings s;
  if (opt.until > 0) os.end_time = opt.until;
  if (opt.fps > 0) os.fps = opt.fps;
  if (!opt.formats.empty()) {
    s.formats = parse_output_formats(opt.formats, "--format");
  } else {
    std::string list;
    for (const auto& f : os.formats) list += (list.empty() ? "" : ",") + f;
    s.formats = list.empty() ? OutputFormats{} : parse_output_formats(list, "output.formats");
  }
  if (!opt.color_by.empty()) os.color_by = opt.color_by;
  s.ropt.color_by = parse_color_by(os.color_by, "--color-by");
  s.ropt.up_axis = os.up_axis;
  s.sopt.format = parse_surface_format(opt.surface_format);
  s.sopt.threads = max_threads();
  validate(s.sopt);
  s.os = std::move(os);
  return s;
}

// Everything a run writes after run.json, and when: the frames at the output rate (particle files,
// pictures, surfaces, a row of bodies.csv per floating body), probes.csv when the clock passes
// k * probes_every, and checkpoint.bin every checkpoint_every frames, with the loop state it keeps.
// Building it writes nothing, nor does a resume's reading of the checkpoint and the logs.
template <int Dim, class Real>
class RunOutputs {
 public:
  RunOutputs(Simulation<Dim, Real>& sim, const Scene<Dim, Real>& scene, RunOutputSettings settings,
             const RunOptions& opt, const std::filesystem::path& out)
      : sim_(sim),
        root_(distributed::world().rank() == 0),
        opt_(opt),
        set_(std::move(settings)),
        out_(out),
        png_dir_(out / "png"),
        surface_dir_(out / "surface"),
        ckpt_path_(out / kCheckpointFile),
        frames_(out, set_.formats, fluid_rows(sim)),
        frame_dt_(1.0 / set_.os.fps),
        probing_(!scene.probes.empty()),
        sampler_(scene.probes, scene.solver.density_kernel, double(scene.solver.support),
                 double(scene.spacing)),
        probe_log_(out / "probes.csv", probe_columns(scene.probes, Dim)),
        probes_every_(scene.probes_every),
        floating_(!sim.body_states().empty()),
        body_log_(out / "bodies.csv",
                  {"body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz"}) {
    // Pictures show what the water hits: every wall, obstacle, gate and floating body in grey, a 3D
    // tank's near walls cut away (the frames hold the fluid only; bodies.csv the bodies).
    set_.ropt.solid = [&s = sim](std::size_t i) {
      return s.particles().kind[i] == static_cast<std::uint8_t>(ParticleKind::Boundary);
    };
    set_.ropt.solid_radius = 0.5 * double(scene.spacing);
    rbox_.lo = scene.view_lo;
    rbox_.hi = scene.view_hi;
  }

  // For --resume: the checkpoint's simulation and frame counter, and the rows of the frame index,
  // probes.csv and bodies.csv up to its time; the probe schedule follows from the time alone. A run
  // killed before its first checkpoint starts again from t = 0: it is deterministic, so that gives
  // exactly what continuing would have.
  void resume(bool quiet) {
    if (!std::filesystem::exists(ckpt_path_)) {
      if (!quiet)
        std::fprintf(stderr, "cellsph: %s has no checkpoint yet; starting again from t = 0\n",
                     out_.string().c_str());
      return;
    }
    reject_old_checkpoint(ckpt_path_);
    loop_.decode(read_simulation_checkpoint(ckpt_path_, sim_), ckpt_path_);
    frames_.resume(loop_.next_frame);
    // probes.csv keeps its rows up to the checkpoint's time: each was flushed before that checkpoint.
    if (probing_) {
      probe_log_.resume(double(sim_.time()));
      while (probes_due()) ++next_probe_;
    }
    if (floating_) body_log_.resume(double(sim_.time()));
  }

  // The folders of the pictures and surfaces asked for.
  void make_folders() const {
    if (!root_) return;
    if (opt_.render) make_folder(png_dir_);
    if (opt_.surface) make_folder(surface_dir_);
  }

  // One row of probes.csv when the clock has passed the next sample time (one row per step at most).
  void sample_probes() {
    if (!probes_due()) return;
    sim_.gather_for_output();
    if (root_) probe_log_.add(double(sim_.time()), sampler_.sample(sim_.particles()));
    while (probes_due()) ++next_probe_;
  }

  // Every frame due at the current time: after a step, one or more (fps above 1 / dt); at the start,
  // frame 0 of a new run, or on a resume those that a checkpoint taken between two frames of one step
  // left unwritten (none in the common case).
  void write_due_frames() {
    while (double(sim_.time()) >= double(loop_.next_frame) * frame_dt_ * (1 - 1e-12)) write_frame();
  }

  void write_checkpoint() {
    sim_.gather_for_output();
    if (!root_) return;
    if (probing_) probe_log_.flush();
    if (floating_) body_log_.flush();  // every row up to the checkpoint's time is on disk first
    write_simulation_checkpoint(sim_, loop_.encode(), ckpt_path_);
  }

  // The end state too, so that a finished run can be extended with --resume DIR --until LATER.
  void write_end_checkpoint() {
    if (set_.os.checkpoint_every > 0) {
      Stopwatch sw;
      write_checkpoint();
      output_ms_ += sw.ms();
    }
  }

  void flush_probes() {
    if (probing_ && root_) probe_log_.flush();
  }

  // The pictures as movie.mp4, where ffmpeg is installed; the message says which.
  void write_movie() const {
    const auto v = make_mp4(png_dir_, "frame_%05d.png", set_.os.fps, out_ / "movie.mp4");
    std::fprintf(stderr, "cellsph: %s\n", v.message.c_str());
  }

  [[nodiscard]] const OutputSettings& settings() const { return set_.os; }
  [[nodiscard]] std::uint64_t next_frame() const { return loop_.next_frame; }
  [[nodiscard]] double output_ms() const { return output_ms_; }

 private:
  // The rows of the frames: the fluid particles (of the particles the simulation shows when a frame is
  // written: in a run across ranks, those gathered on rank 0).
  static CsvRowFilter fluid_rows(const Simulation<Dim, Real>& sim) {
    return [&s = sim](std::size_t i) {
      return s.particles().kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid);
    };
  }

  [[nodiscard]] bool probes_due() const {
    return probing_ && double(sim_.time()) >= double(next_probe_) * probes_every_ * (1 - 1e-12);
  }

  void write_frame() {
    Stopwatch sw;
    const double t = double(sim_.time());
    sim_.gather_for_output();
    if (root_) write_frame_files(t);
    ++loop_.next_frame;
    if (set_.os.checkpoint_every > 0 &&
        loop_.next_frame % static_cast<std::uint64_t>(set_.os.checkpoint_every) == 0)
      write_checkpoint();
    output_ms_ += sw.ms();
  }

  void write_frame_files(double t) {
    if (set_.formats.any()) frames_.write(sim_.particles(), loop_.next_frame, t);
    if (opt_.render)
      render_png(sim_.particles(), set_.ropt, rbox_, t, png_dir_ / frame_file_name(loop_.next_frame, "png"));
    if (opt_.surface) write_surfaces(sim_.particles(), set_.sopt, surface_dir_, loop_.next_frame);
    if (probing_) probe_log_.flush();
    if (floating_) write_body_rows(t);
  }

  void write_body_rows(double t) {
    const auto& st = sim_.body_states();
    for (std::size_t b = 0; b < st.size(); ++b) {
      const auto& s = st[b];
      body_log_.add(t, {double(b), s.x[0], s.x[1], s.x[2], s.q[0], s.q[1], s.q[2], s.q[3], s.v[0], s.v[1],
                        s.v[2], s.w[0], s.w[1], s.w[2]});
    }
    body_log_.flush();
  }

  Simulation<Dim, Real>& sim_;
  // Rank 0 writes every file; in a run across ranks the others only take part in the gathers.
  bool root_;
  const RunOptions& opt_;
  RunOutputSettings set_;
  RenderBox rbox_;
  std::filesystem::path out_, png_dir_, surface_dir_, ckpt_path_;
  FrameOutput<Dim, Real> frames_;
  LoopState loop_;
  double frame_dt_;
  double output_ms_ = 0;
  bool probing_;
  ProbeSampler<Dim, Real> sampler_;
  ProbeLog probe_log_;
  double probes_every_;
  std::uint64_t next_probe_ = 0;
  bool floating_;
  ProbeLog body_log_;
};

// Where this invocation's stepping started: the progress line's rate and the summary count from here.
struct RunStart {
  Stopwatch wall;
  std::uint64_t steps = 0;
  double time = 0;
};

template <int Dim, class Real>
void print_run_header(const Scene<Dim, Real>& scene, const std::string& source,
                      const Simulation<Dim, Real>& sim, const std::filesystem::path& out) {
  const auto& cfg = scene.solver;
  std::fprintf(stderr, "cellsph: %s (%s): %zu particles (%zu fluid), %dD %s, %s, %s, %d threads -> %s\n",
               scene.header.name.c_str(), source.c_str(), sim.particles().size(), sim.fluid_count(), Dim,
               sizeof(Real) == 4 ? "float" : "double", std::string(model_name(cfg.model)).c_str(),
               std::string(method_name(cfg.search.method)).c_str(), max_threads(), out.string().c_str());
  for (const auto& d : scene.derived)
    std::fprintf(stderr, "cellsph: %s = %.6g (not in the scene: %s)\n", d.key.c_str(), d.value,
                 d.why.c_str());
}

template <int Dim, class Real>
std::string progress_line(const Simulation<Dim, Real>& sim, const RunStart& start, std::uint64_t next_frame,
                          double end_time) {
  const double w = start.wall.seconds();
  return "t=" + format_number("%.4f", double(sim.time())) + "/" + format_number("%.4g", end_time) +
         " s  frame " + std::to_string(next_frame) + "  " +
         format_number("%.0f", double(sim.steps() - start.steps) / std::max(w, 1e-9)) + " steps/s  " +
         std::to_string(sim.fluid_count()) + " fluid particles" + sim.solver_progress() +
         (sim.wall_corrections() > 0 ? "  put back from walls " + std::to_string(sim.wall_corrections())
                                     : "");
}

// The solid guard's count (boundary/solid_guard.hpp) for the summary, with a warning when it put back more
// than kWallCorrectionWarning of the fluid per simulated second: the walls' pressure is too weak to stop
// what the flow throws at them.
template <int Dim, class Real>
void print_wall_corrections(const Simulation<Dim, Real>& sim, double simulated) {
  const std::uint64_t n = sim.wall_corrections();
  if (n == 0) return;
  const double rate =
      double(n) / std::max<double>(1, double(sim.fluid_count())) / std::max(simulated, 1e-300);
  std::fprintf(stderr,
               "         walls: %llu fluid particles put back out of a wall or obstacle (%.3g%% of the fluid "
               "per simulated second)\n",
               static_cast<unsigned long long>(n), 100 * rate);
  if (rate > kWallCorrectionWarning)
    std::fprintf(stderr,
                 "         warning: over %.3g%% of the fluid per second: the walls or the speed of sound are "
                 "too weak for this flow; raise /solver/eos/stiffness, or try /boundary/model \"adami\"\n",
                 100 * kWallCorrectionWarning);
}

// Steps until --steps or the end time, or until a stop signal, sampling the probes and writing the frames
// as they fall due, with a progress line after each step.
template <int Dim, class Real>
void step_until_done(Simulation<Dim, Real>& sim, RunOutputs<Dim, Real>& outputs, Progress& progress,
                     const RunStart& start, const RunOptions& opt, CompressibilityWatch<Dim, Real>& watch) {
  const double end_time = outputs.settings().end_time;
  auto done = [&] {
    if (opt.steps >= 0) return sim.steps() >= static_cast<std::uint64_t>(opt.steps);
    return double(sim.time()) >= end_time * (1 - 1e-12);
  };
  std::uint64_t max_iteration_hits_seen = 0;
  try {
    outputs.sample_probes();
    outputs.write_due_frames();
    const bool across_ranks = sim.distributed();
    while (!done() && !stop_signal(across_ranks)) {
      sim.step();
      warn_max_iterations(sim, progress, max_iteration_hits_seen);
      outputs.sample_probes();
      const std::uint64_t frames = outputs.next_frame();
      outputs.write_due_frames();
      if (outputs.next_frame() != frames && distributed::world().rank() == 0)
        warn_compressibility(sim, progress, watch);
      const double frac = opt.steps >= 0
                              ? double(sim.steps()) / double(std::max<long>(opt.steps, 1))
                              : (double(sim.time()) - start.time) / std::max(end_time - start.time, 1e-300);
      progress.update(frac, progress_line(sim, start, outputs.next_frame(), end_time));
    }
  } catch (...) {
    progress.finish();  // the error's line starts on a line of its own
    throw;
  }
  progress.finish();
}

// The summary: simulated time, wall time, steps and frames, where the time went, and the model's own lines
// (the implicit solvers' figures, models/<model>_stepper.hpp).
template <int Dim, class Real>
void print_summary(const Simulation<Dim, Real>& sim, const RunStart& start,
                   const RunOutputs<Dim, Real>& outputs, const CompressibilityWatch<Dim, Real>& watch,
                   const std::filesystem::path& out) {
  const double w = start.wall.seconds();
  const auto& tm = sim.timings();
  const std::uint64_t steps = sim.steps() - start.steps;
  const double output_ms = outputs.output_ms();
  const double total_ms = tm.neighbors + tm.forces + tm.integration + output_ms;
  auto pct = [&](double ms) { return format_number("%.0f%%", 100.0 * ms / std::max(total_ms, 1e-9)); };
  std::fprintf(
      stderr,
      "cellsph: done: simulated %.4g s in %s wall, %llu steps (mean dt %.3g s), %llu frames in %s\n"
      "         time split: neighbours %s, forces %s, integration %s, output %s\n",
      double(sim.time()), Progress::format_duration(w).c_str(), static_cast<unsigned long long>(steps),
      steps ? (double(sim.time()) - start.time) / double(steps) : 0.0,
      static_cast<unsigned long long>(outputs.next_frame()), out.string().c_str(), pct(tm.neighbors).c_str(),
      pct(tm.forces).c_str(), pct(tm.integration).c_str(), pct(output_ms).c_str());
  for (const std::string& line : sim.solver_summary()) std::fprintf(stderr, "         %s\n", line.c_str());
  for (const std::string& line : watch.given()) std::fprintf(stderr, "         warning: %s\n", line.c_str());
  print_wall_corrections(sim, double(sim.time()) - start.time);
  if (sim.distributed()) {
    const RankStats& r = sim.rank_stats();
    std::fprintf(
        stderr,
        "         ranks: %d, domain rebuilt %llu times, rebalanced %llu times; work imbalance %.1f%% at "
        "the last rebuild, %.1f%% at most (times above are rank 0's)\n",
        r.ranks, static_cast<unsigned long long>(r.rebuilds), static_cast<unsigned long long>(r.rebalances),
        100 * r.imbalance, 100 * r.max_imbalance);
  }
}

// Stopped between two steps: the state after the last step, with its frame counter, so the resume
// continues exactly as the run would have (frames after the last one written follow on resume).
template <int Dim, class Real>
int stop_with_checkpoint(int sig, const Simulation<Dim, Real>& sim, RunOutputs<Dim, Real>& outputs,
                         const RunOptions& given, const std::filesystem::path& out) {
  outputs.write_checkpoint();
  if (distributed::world().rank() != 0) return 128 + sig;
  std::fprintf(stderr,
               "cellsph: stopped by %s at t = %.6g s, step %llu, after frame %llu, in %s; checkpoint "
               "written\ncellsph: to continue: %s\n",
               signal_name(sig), double(sim.time()), static_cast<unsigned long long>(sim.steps()),
               static_cast<unsigned long long>(outputs.next_frame()) - 1, out.string().c_str(),
               resume_command(given, out).c_str());
  return 128 + sig;
}

// Runs one scene. Two phases: first everything is read, validated and built (scene, options,
// particles, Simulation, the checkpoint and the frame index of a resume) without writing anything, so a
// failed start leaves the output location as it was; then `start_output` makes the folder and run.json,
// and the frames follow.
template <int Dim, class Real>
int run_scene(const nlohmann::json& scene_json, const std::string& source, const RunOptions& opt,
              const RunOptions& given, const std::filesystem::path& out, bool resuming,
              const std::function<void(const std::vector<DerivedSetting>&)>& start_output) {
  Scene<Dim, Real> scene = load_scene<Dim, Real>(scene_json, source);
  apply_solver_options(scene.solver, opt, source);
  RunOutputSettings settings = output_settings(scene.output, opt);
  Simulation<Dim, Real> sim(scene.solver, std::move(scene.particles));
  RunOutputs<Dim, Real> outputs(sim, scene, std::move(settings), opt, out);  // writes nothing yet
  if (resuming) outputs.resume(opt.quiet);
  // Under mpirun: every rank built the same particles (and read the same checkpoint); each keeps its part.
  sim.distribute(distributed::world());
  const bool root = distributed::world().rank() == 0;  // the one rank that writes and reports
  const bool quiet = opt.quiet || !root;

  // ---- Everything is valid: from here on the run writes.
  if (const int sig = stop_signal(sim.distributed())) {
    if (root)
      std::fprintf(stderr, "cellsph: stopped by %s before the run started; nothing was written\n",
                   signal_name(sig));
    return 128 + sig;
  }
  if (root) start_output(scene.derived);
  outputs.make_folders();

  Progress progress(quiet);
  const RunStart start{Stopwatch{}, sim.steps(), double(sim.time())};
  if (!quiet) print_run_header(scene, source, sim, out);
  if (root)
    for (const auto& w : scene.warnings) std::fprintf(stderr, "cellsph: warning: %s\n", w.c_str());
  CompressibilityWatch<Dim, Real> watch;
  step_until_done(sim, outputs, progress, start, opt, watch);
  outputs.flush_probes();
  if (const int sig = stop_signal(sim.distributed()))
    return stop_with_checkpoint(sig, sim, outputs, given, out);
  outputs.write_end_checkpoint();
  if (opt.render && !quiet) outputs.write_movie();
  if (!quiet) print_summary(sim, start, outputs, watch, out);
  return 0;
}

// For --resume: the scene and the options of the original run, from DIR/run.json (an option given again
// on this command line keeps the new value).
void load_saved_run(RunOptions& opt, nlohmann::json& scene_json, std::string& source) {
  const std::filesystem::path out = opt.resume;
  const auto run_file = out / kRunFile;
  if (!std::filesystem::exists(run_file))
    throw InputError("--resume " + out.string() + ": no " + kRunFile +
                     " there (not a cellsph output folder)");
  const auto saved = JsonReader::parse_file(run_file);
  try {
    scene_json = saved.at("scene");
    source = saved.at("source").get<std::string>();
    const auto& o = saved.at("options");
    if (opt.method.empty()) opt.method = o.at("method").get<std::string>();
    // A checkpoint does not depend on the backend: a resume may pick another one.
    if (opt.backend.empty() && o.contains("backend")) opt.backend = o.at("backend").get<std::string>();
    if (opt.fps <= 0) opt.fps = o.at("fps").get<double>();
    if (opt.formats.empty()) opt.formats = o.at("formats").get<std::string>();
    if (opt.until <= 0) opt.until = o.at("until").get<double>();
    if (opt.steps < 0) opt.steps = o.at("steps").get<long>();
    if (!opt.render) opt.render = o.at("render").get<bool>();
    if (opt.color_by.empty()) opt.color_by = o.at("color_by").get<std::string>();
    if (!opt.surface) opt.surface = o.at("surface").get<bool>();
    if (o.contains("surface_format")) opt.surface_format = o.at("surface_format").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(run_file.string() + ": damaged (" + e.what() + ")");
  }
  if (!opt.sets.empty())
    throw InputError("--set: not with --resume (a resumed run keeps the scene saved in " + run_file.string() +
                     ")");
}

// Option errors come before the scene is built.
void check_options(const RunOptions& opt) {
  parse_surface_format(opt.surface_format);
  if (!opt.method.empty() && !parse_method(opt.method))
    throw InputError("--method: unknown method '" + opt.method + "' (expected " + method_names_joined() +
                     ")");
  if (!opt.formats.empty()) parse_output_formats(opt.formats, "--format");
  if (!opt.backend.empty()) {
    const auto b = parse_backend(opt.backend);
    if (!b) throw InputError("--backend: unknown backend '" + opt.backend + "' (expected cpu or cuda)");
    require_backend(*b, "--backend");  // before anything is written: no build, device or driver
  }
  if (!opt.color_by.empty()) parse_color_by(opt.color_by, "--color-by");
}

// The first writes of a run, once everything is valid. What writers killed in this folder before left is
// removed (a run killed mid-write, then resumed or started again into the same folder); a new run makes
// the folder and run.json, the scene and options a resume reads back.
void start_output(const std::filesystem::path& out, bool new_run, const nlohmann::json& scene_json,
                  const std::string& source, const RunOptions& opt,
                  const std::vector<DerivedSetting>& derived) {
  for (const auto& d : {out, out / "png", out / "surface"}) remove_stale_temporaries(d);
  if (!new_run) return;
  make_folder(out);
  nlohmann::json saved;
  saved["scene"] = scene_json;
  saved["source"] = source;
  saved["options"] = {{"method", opt.method},   {"backend", opt.backend},
                      {"fps", opt.fps},         {"formats", opt.formats},
                      {"until", opt.until},     {"steps", opt.steps},
                      {"render", opt.render},   {"color_by", opt.color_by},
                      {"surface", opt.surface}, {"surface_format", opt.surface_format}};
  // What the scene left out and load_scene derived from it (a resume derives it again, alike).
  saved["derived"] = nlohmann::json::array();
  for (const auto& d : derived)
    saved["derived"].push_back({{"key", d.key}, {"value", d.value}, {"why", d.why}});
  write_file_atomic(out / kRunFile, saved.dump(2) + "\n");
}

int run_command(RunOptions opt) {
  // From the start, so that a Ctrl-C while the scene loads still ends with code 130 and nothing written.
  install_stop_handlers();
  const RunOptions given = opt;
  nlohmann::json scene_json;
  std::string source;
  std::filesystem::path out;
  bool resuming = false;
  if (!opt.resume.empty()) {
    out = opt.resume;
    load_saved_run(opt, scene_json, source);
    resuming = true;
  } else {
    if (opt.scene.empty()) opt.scene = kDefaultScene;
    scene_json = read_scene_json(opt.scene, source);
    apply_scene_edits(scene_json, opt.sets, source);
  }
  const SceneHeader header = read_scene_header(scene_json, source);
  if (out.empty())
    out = opt.out.empty() ? std::filesystem::path(header.name) : std::filesystem::path(opt.out);
  check_options(opt);

  // Called by run_scene once everything is valid.
  const bool new_run = opt.resume.empty();
  auto first_writes = [&](const std::vector<DerivedSetting>& derived) {
    start_output(out, new_run, scene_json, source, opt, derived);
  };

  ScopedThreads threads(opt.threads);
  if (header.dim == 2)
    return header.single_precision
               ? run_scene<2, float>(scene_json, source, opt, given, out, resuming, first_writes)
               : run_scene<2, double>(scene_json, source, opt, given, out, resuming, first_writes);
  return header.single_precision
             ? run_scene<3, float>(scene_json, source, opt, given, out, resuming, first_writes)
             : run_scene<3, double>(scene_json, source, opt, given, out, resuming, first_writes);
}

}  // namespace

void register_run(CLI::App& app, int& result) {
  auto opt = std::make_shared<RunOptions>();
  auto* sub = app.add_subcommand(
      "run", "Run a scene (built-in name or JSON file; default: " + std::string(kDefaultScene) + ")");
  sub->add_option("scene", opt->scene, "Built-in scene name (see `cellsph scenes`) or a scene .json file");
  sub->add_option("--out", opt->out, "Output folder (default: a folder named after the scene)");
  sub->add_option("--threads", opt->threads, "Worker threads (default: all cores)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--method", opt->method,
                  "Neighbour search: " + method_names_joined() + " (default: the scene's, else cell-index)");
  sub->add_option("--backend", opt->backend,
                  "Where the steps run: cpu or cuda (default: the scene's solver.backend, else cpu)");
  sub->add_option("--until", opt->until, "Simulated end time in seconds (default: the scene's time.end)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--steps", opt->steps, "Stop after this many steps instead of at an end time")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--fps", opt->fps, "Output frames per simulated second (default: the scene's output.fps)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--format", opt->formats,
                  "Frame formats, any of vtu,ply,csv (default: the scene's output.formats)");
  sub->add_flag("--render", opt->render,
                "Also write a PNG picture per frame (and an MP4 if ffmpeg is installed)");
  sub->add_option("--color-by", opt->color_by,
                  "Picture colours: phase, speed or pressure (default: the scene's)");
  sub->add_flag("--surface", opt->surface,
                "Also write the fluid surface per frame and phase (surface/surface_PHASE_NNNNN.ply), see "
                "docs/surfaces.md");
  sub->add_option("--surface-format", opt->surface_format, "Surface mesh format: ply or obj (default: ply)");
  sub->add_flag("--quiet", opt->quiet, "No progress line and no summary");
  sub->add_option("--resume", opt->resume, "Continue the run in this output folder from its last checkpoint");
  sub->add_option("--set", opt->sets,
                  "Edit the scene before the run: /json/pointer=value (a JSON value, else a string; null "
                  "removes the key), e.g. "
                  "--set /spacing=0.01 --set /boundary/model=akinci; repeatable; saved in run.json");
  sub->callback([opt, &result] { result = run_command(*opt); });
}

}  // namespace cellsph::app
