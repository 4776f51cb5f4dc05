#pragma once
// printf's rendering of one number as a std::string: format_number("%.3g", 0.012345) == "0.0123". For
// the messages, progress lines and summaries, whose numbers are printed the way printf prints them.
#include <cstdio>
#include <string>

namespace cellsph {

inline std::string format_number(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace cellsph
