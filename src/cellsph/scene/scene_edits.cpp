// `--set` edits of a scene's JSON before it is read (apply_scene_edits, declared in scene.hpp).
#include "cellsph/scene/scene.hpp"

#include <algorithm>
#include <cstdio>
#include <string_view>

#include "cellsph/scene/json_reader.hpp"

namespace cellsph {

namespace {

// Offset of the first byte of `s` that is not part of well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF), or npos. A JSON string must be UTF-8: nlohmann's parser checks
// the scene file, this the --set values that are taken as strings verbatim.
std::size_t invalid_utf8_at(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
    if (c < 0x80) {
      ++i;
      continue;
    }
    if (c >= 0xC2 && c <= 0xDF) {
      n = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 2;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 3;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return i;
    }
    if (s.size() - i <= n) return i;
    for (std::size_t k = 1; k <= n; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF)) return i;
    }
    i += n + 1;
  }
  return std::string_view::npos;
}

// Refuses an edit whose pointer would grow an array by more than one element: nlohmann's operator[]
// fills every index up to the one named, so /phases/100000000/viscosity would make 10^8 values (and a
// 30-byte input to fuzz/scene_fuzz.cpp 44 million). One past the end appends, like "-".
void check_array_indices(const nlohmann::json& j, const std::string& edit, const std::string& pointer) {
  std::vector<std::string> tokens;
  for (nlohmann::json::json_pointer p(pointer); !p.empty(); p.pop_back()) tokens.push_back(p.back());
  std::reverse(tokens.begin(), tokens.end());  // root first
  const nlohmann::json* cur = &j;              // nullptr once the path leaves what exists
  std::string path;
  for (const auto& t : tokens) {
    const bool digits =
        !t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    const bool array = cur ? cur->is_array() : false;
    if (digits && (array || !cur || cur->is_null())) {
      const std::size_t size = array ? cur->size() : 0;
      if (t.size() > 9 || std::stoul(t) > size)
        throw InputError("--set '" + edit + "': index " + t + " is beyond the end of " +
                         (path.empty() ? "/" : path) + " (" + std::to_string(size) +
                         " elements: the next is " + std::to_string(size) + " or -)");
      cur = std::stoul(t) < size ? &(*cur)[std::stoul(t)] : nullptr;
    } else {
      cur = cur && cur->is_object() && cur->contains(t) ? &(*cur)[t] : nullptr;
    }
    path += "/" + t;
  }
}

}  // namespace

void apply_scene_edits(nlohmann::json& j, const std::vector<std::string>& edits, std::string& source) {
  if (edits.empty()) return;
  std::string list;
  for (const auto& e : edits) {
    if (const auto bad = invalid_utf8_at(e); bad != std::string_view::npos) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(e[bad])));
      throw InputError("--set: edit " + json_value_text(nlohmann::json(e.substr(0, bad))) +
                       "... is not valid UTF-8 (byte " + hex + " at offset " + std::to_string(bad) + ")");
    }
    const auto eq = e.find('=');
    if (eq == std::string::npos || eq == 1 || e[0] != '/')
      throw InputError("--set '" + e + "': expected /json/pointer=value, e.g. /phases/0/viscosity=1");
    const std::string text = e.substr(eq + 1);
    if (text.empty()) throw InputError("--set '" + e + "': no value after '='");
    nlohmann::json value = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = text;
    try {
      const nlohmann::json::json_pointer ptr(e.substr(0, eq));
      if (value.is_null()) {  // null removes the key (no scene key takes null)
        if (!j.contains(ptr))
          throw InputError("--set '" + e + "': " + ptr.to_string() + " is not in the scene");
        nlohmann::json& parent = j[ptr.parent_pointer()];
        if (parent.is_array())
          parent.erase(static_cast<std::size_t>(std::stoul(ptr.back())));
        else
          parent.erase(ptr.back());
      } else {
        check_array_indices(j, e, e.substr(0, eq));
        j[ptr] = std::move(value);
      }
    } catch (const nlohmann::json::exception& ex) {
      throw InputError("--set '" + e + "': " + ex.what());
    }
    list += (list.empty() ? "" : " ") + e;
  }
  source += " (edited: " + list + ")";
}

}  // namespace cellsph
