// `cellsph neighbors`: every neighbour pair of a point set, CSV in, CSV out (the contract of issue 2,
// documented in docs/neighbor-search.md).
//
// Order of work: check the options, read the input (all bad input is reported before anything is
// written), open the output's temporary file, search, write, rename. An error at any point leaves no
// output file behind (AtomicFile removes its temporary file).
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/points_csv.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "commands.hpp"

namespace cellsph::app {

namespace {

struct NeighborsArgs {
  std::string input;
  std::string output;
  std::string radius;  // parsed here, strictly, so the message can quote it
  bool radius_given = false;
  std::string method = "cell-index";
  int subdivision = 1;
  int threads = 0;
  bool threads_given = false;
  bool counts = false;
  bool stats = false;
  bool unsorted_rows = false;
};

// Output is formatted by hand into a large buffer: ostream << per number is ~10x slower, and the
// lists of 10^6 particles hold tens of millions of rows.
class CsvWriter {
 public:
  explicit CsvWriter(std::ostream& out) : out_(out) { buf_.resize(kSize); }
  ~CsvWriter() = default;
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void text(std::string_view s) {
    reserve(s.size());
    s.copy(buf_.data() + used_, s.size());
    used_ += s.size();
  }
  void row(std::uint64_t a, std::uint64_t b) {
    reserve(48);
    char* p = buf_.data() + used_;
    char* const end = buf_.data() + buf_.size();
    p = std::to_chars(p, end, a).ptr;
    *p++ = ',';
    p = std::to_chars(p, end, b).ptr;
    *p++ = '\n';
    used_ = static_cast<std::size_t>(p - buf_.data());
  }
  void flush() {
    out_.write(buf_.data(), static_cast<std::streamsize>(used_));
    used_ = 0;
  }

 private:
  static constexpr std::size_t kSize = std::size_t{1} << 22;
  void reserve(std::size_t n) {
    if (used_ + n > buf_.size()) flush();
  }
  std::ostream& out_;
  std::vector<char> buf_;
  std::size_t used_ = 0;
};

template <int Dim>
void run(const NeighborsArgs& a, double radius, Method method, const PointsTable& table, AtomicFile& out) {
  using Real = double;
  const auto x = table.points<Dim, Real>();
  NeighborSearch<Dim, Real> ns(
      {.method = method, .subdivision = a.subdivision, .sorted_rows = !a.unsorted_rows});
  if (table.has_h())
    ns.build(x, std::span<const Real>(table.h));
  else
    ns.build(x, static_cast<Real>(radius));
  NeighborList nl;
  ns.find_all(nl);

  if (a.stats) {
    const SearchStats& s = ns.stats();
    char line[256];
    std::snprintf(line, sizeof line,
                  "method=%s build_ms=%.3f query_ms=%.3f pairs=%llu candidates=%llu memory_bytes=%llu\n",
                  std::string(method_name(method)).c_str(), s.build_ms, s.query_ms,
                  static_cast<unsigned long long>(s.pairs), static_cast<unsigned long long>(s.candidates),
                  static_cast<unsigned long long>(s.memory_bytes));
    std::cerr << line << std::flush;
  }

  CsvWriter w(out.stream());
  const std::size_t n = nl.size();
  if (a.counts) {
    w.text("i,count\n");
    for (std::size_t i = 0; i < n; ++i) w.row(i, nl.count(i));
  } else {
    w.text("i,j\n");
    for (std::size_t i = 0; i < n; ++i)
      for (const std::uint32_t* j = nl.begin(i); j != nl.end(i); ++j) w.row(i, *j);
  }
  w.flush();
}

void run_neighbors(const NeighborsArgs& a) {
  const auto method = parse_method(a.method);
  if (!method)
    throw InputError("--method: unknown method '" + a.method + "' (expected one of " + method_names_joined() +
                     ")");
  if (a.subdivision < 1)
    throw InputError("--subdivision: must be an integer >= 1, got " + std::to_string(a.subdivision));
  if (a.threads_given && a.threads < 1)
    throw InputError("--threads: must be an integer >= 1, got " + std::to_string(a.threads));
  double radius = 0;
  if (a.radius_given) {
    const char* first = a.radius.data();
    const char* last = first + a.radius.size();
    const auto [ptr, ec] = std::from_chars(first, last, radius);
    if (ec != std::errc() || ptr != last || !std::isfinite(radius) || !(radius > 0))
      throw InputError("--radius: must be a finite number > 0, got '" + a.radius + "'");
  }

  const PointsTable table = read_points_csv(a.input);
  if (!a.radius_given && !table.has_h())
    throw InputError("--radius is required: points file '" + a.input + "' has no 'h' column");

  AtomicFile out(a.output);
  ScopedThreads threads(a.threads_given ? a.threads : max_threads());
  if (table.dim == 2)
    run<2>(a, radius, *method, table, out);
  else
    run<3>(a, radius, *method, table, out);
  out.commit();
}

}  // namespace

void register_neighbors(CLI::App& app, int& result) {
  auto args = std::make_shared<NeighborsArgs>();
  auto* sub = app.add_subcommand("neighbors", "Find all neighbours of a point set (CSV in, CSV out)");
  sub->add_option("--input", args->input, "CSV with header x,y or x,y,z (optional h column)")
      ->required()
      ->type_name("FILE");
  auto* radius =
      sub->add_option("--radius", args->radius, "support length h (> 0); an 'h' column overrides it")
          ->type_name("R");
  sub->add_option("--method", args->method, "search method: " + method_names_joined())->capture_default_str();
  sub->add_option("--subdivision", args->subdivision, "subdivision factor H: cells of size h/H (>= 1)")
      ->capture_default_str();
  auto* threads = sub->add_option("--threads", args->threads, "threads (>= 1; default: all cores)");
  sub->add_flag("--counts", args->counts, "write i,count (neighbours per particle) instead of i,j pairs");
  sub->add_flag("--stats", args->stats, "print one line of search statistics to stderr");
  sub->add_flag("--unsorted-rows", args->unsorted_rows,
                "cell-index lists each particle's neighbours in its own order (the same for the same input) "
                "instead of ascending, and skips sorting them; other methods list them ascending");
  sub->add_option("--output", args->output, "output CSV (written atomically)")->required()->type_name("FILE");
  sub->callback([args, radius, threads, &result] {
    args->radius_given = radius->count() > 0;
    args->threads_given = threads->count() > 0;
    run_neighbors(*args);
    result = 0;
  });
}

}  // namespace cellsph::app
