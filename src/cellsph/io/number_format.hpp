#pragma once
// Shortest decimal text that reads back to the same value (std::to_chars), for every text output.
#include <charconv>
#include <string>
#include <system_error>

namespace cellsph::io {

// Appends the shortest round-trip representation of v to out.
template <class T>
inline void append_number(std::string& out, T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

template <class T>
inline std::string number_text(T v) {
  std::string s;
  append_number(s, v);
  return s;
}

// Parses a whole string as a number; false if it is not one (used by the readers for --resume).
template <class T>
inline bool parse_number(std::string_view text, T& v) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

}  // namespace cellsph::io
