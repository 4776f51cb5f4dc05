#include "cellsph/scene/json_reader.hpp"

#include <fstream>
#include <sstream>

namespace cellsph {

std::string json_value_text(const nlohmann::json& v) {
  // Invalid UTF-8 (only a --set value can hold it: apply_scene_edits refuses it) is shown replaced.
  std::string s = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

namespace {

// "FILE:LINE:COLUMN" of the byte at `offset` (0-based) of `text`.
std::string where_in(const std::filesystem::path& file, const std::string& text, std::size_t offset) {
  std::size_t line = 1, col = 1;
  for (std::size_t k = 0; k < offset && k < text.size(); ++k) {
    if (text[k] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return file.string() + ":" + std::to_string(line) + ":" + std::to_string(col);
}

}  // namespace

nlohmann::json JsonReader::parse_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open scene file");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte: 1-based offset of the byte after the error.
    throw InputError(where_in(file, text, e.byte > 0 ? e.byte - 1 : 0) + ": invalid JSON (" +
                     std::string(e.what()) + ")");
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double (1e400): the message quotes it; name where it first appears.
    std::string what = e.what(), number;
    const auto q0 = what.find('\''), q1 = what.rfind('\'');
    if (q0 != std::string::npos && q1 > q0) number = what.substr(q0 + 1, q1 - q0 - 1);
    const auto at = number.empty() ? std::string::npos : text.find(number);
    throw InputError((at == std::string::npos ? file.string() : where_in(file, text, at)) +
                     ": invalid JSON (" +
                     (number.empty() ? what : "number " + number + " is beyond the range of a double") + ")");
  }
}

void JsonReader::fail(const std::string& key, const std::string& what) const {
  throw InputError(file_ + ": " + key_path(key) + ": " + what);
}

void JsonReader::fail_here(const std::string& what) const {
  throw InputError(file_ + ": " + (path_.empty() ? "/" : path_) + ": " + what);
}

const nlohmann::json& JsonReader::at(const std::string& key) {
  read_.insert(key);
  return (*j_)[key];
}

JsonReader JsonReader::child(const std::string& key) {
  if (!has(key)) fail(key, "missing");
  const auto& v = at(key);
  if (!v.is_object() && !v.is_array()) fail(key, "expected an object or array, got " + json_value_text(v));
  return JsonReader(v, file_, key_path(key));
}

JsonReader JsonReader::element(std::size_t index) const {
  return JsonReader((*j_)[index], file_, path_ + "/" + std::to_string(index));
}

std::size_t JsonReader::array_size() const {
  if (!j_->is_array()) fail_here("expected an array, got " + json_value_text(*j_));
  return j_->size();
}

double JsonReader::number(const std::string& key, double def, double min, double max) {
  if (!has(key)) return def;
  const auto& v = at(key);
  if (!v.is_number()) fail(key, "expected a number, got " + json_value_text(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(key, "expected a finite number, got " + json_value_text(v));
  if (x < min || x > max) {
    std::ostringstream os;
    os << "value " << json_value_text(v) << " out of range [" << min << ", " << max << "]";
    fail(key, os.str());
  }
  return x;
}

double JsonReader::required_number(const std::string& key, double min, double max) {
  if (!has(key)) fail(key, "missing (a number is required)");
  return number(key, 0.0, min, max);
}

long JsonReader::integer(const std::string& key, long def, long min, long max) {
  if (!has(key)) return def;
  const auto& v = at(key);
  if (!v.is_number_integer()) fail(key, "expected an integer, got " + json_value_text(v));
  const long x = v.get<long>();
  if (x < min || x > max)
    fail(key, "value " + json_value_text(v) + " out of range [" + std::to_string(min) + ", " +
                  std::to_string(max) + "]");
  return x;
}

bool JsonReader::boolean(const std::string& key, bool def) {
  if (!has(key)) return def;
  const auto& v = at(key);
  if (!v.is_boolean()) fail(key, "expected true or false, got " + json_value_text(v));
  return v.get<bool>();
}

std::string JsonReader::string(const std::string& key, const std::string& def) {
  if (!has(key)) return def;
  const auto& v = at(key);
  if (!v.is_string()) fail(key, "expected a string, got " + json_value_text(v));
  return v.get<std::string>();
}

std::string JsonReader::choice(const std::string& key, const std::string& def,
                               const std::vector<std::string>& allowed) {
  const std::string s = string(key, def);
  for (const auto& a : allowed)
    if (a == s) return s;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fail(key, "unknown value \"" + s + "\" (expected one of: " + list + ")");
}

std::vector<double> JsonReader::vector(const std::string& key, std::size_t dim, std::vector<double> def) {
  if (!has(key)) return def;
  const auto& v = at(key);
  if (!v.is_array() || v.size() != dim)
    fail(key, "expected an array of " + std::to_string(dim) + " numbers, got " + json_value_text(v));
  std::vector<double> out;
  for (const auto& e : v) {
    if (!e.is_number() || !std::isfinite(e.get<double>()))
      fail(key, "expected an array of " + std::to_string(dim) + " numbers, got " + json_value_text(v));
    out.push_back(e.get<double>());
  }
  return out;
}

std::vector<double> JsonReader::required_vector(const std::string& key, std::size_t dim) {
  if (!has(key)) fail(key, "missing (an array of " + std::to_string(dim) + " numbers is required)");
  return vector(key, dim, {});
}

void JsonReader::finish() const {
  if (!j_->is_object()) return;
  for (const auto& [k, v] : j_->items()) {
    if (!read_.count(k)) fail(k, "unknown key (value " + json_value_text(v) + ")");
  }
}

}  // namespace cellsph
