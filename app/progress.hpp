#pragma once
// Progress of a long run. On a terminal one line is redrawn in place (at most 10 times a second);
// otherwise a plain log line is printed every few seconds, so logs of CI jobs and batch runs stay
// readable.
#include <cstdio>
#include <string>

#include <unistd.h>

#include "cellsph/core/timer.hpp"

namespace cellsph::app {

class Progress {
 public:
  explicit Progress(bool quiet, std::FILE* out = stderr)
      : out_(out), quiet_(quiet), tty_(::isatty(::fileno(out)) != 0) {}

  // `fraction` in [0, 1]; `line` is the status text without the time estimate.
  void update(double fraction, const std::string& line, bool force = false) {
    if (quiet_) return;
    const double now = clock_.seconds();
    const double interval = tty_ ? 0.1 : 5.0;
    if (!force && now - last_ < interval) return;
    last_ = now;
    std::string eta = "--";
    if (fraction > 1e-6 && fraction < 1.0) eta = format_duration(now / fraction - now);
    if (fraction >= 1.0) eta = "0s";
    if (tty_) {
      std::fprintf(out_, "\r\033[K%s  eta %s", line.c_str(), eta.c_str());
      dirty_ = true;
    } else {
      std::fprintf(out_, "[%7.1fs] %s  eta %s\n", now, line.c_str(), eta.c_str());
    }
    std::fflush(out_);
  }

  // Ends the in-place line before other output.
  void finish() {
    if (dirty_) std::fprintf(out_, "\n");
    dirty_ = false;
  }

  static std::string format_duration(double s) {
    char buf[32];
    if (s < 60)
      std::snprintf(buf, sizeof buf, "%.0fs", s);
    else if (s < 3600)
      std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else
      std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buf;
  }

 private:
  Stopwatch clock_;
  std::FILE* out_;
  bool quiet_;
  bool tty_;
  bool dirty_ = false;
  double last_ = -1e9;
};

}  // namespace cellsph::app
