#pragma once
// Strict reading of JSON scene files. Every value is read through a JsonReader that knows the file
// and the key path it came from, so every error names both ("scene.json: /fluids/0/size: expected
// a number, got \"abc\""). finish() rejects keys that were never read: a typo is an error, not a
// silently ignored setting.
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellsph/core/error.hpp"

namespace cellsph {

class JsonReader {
 public:
  JsonReader(const nlohmann::json& j, std::string file, std::string path)
      : j_(&j), file_(std::move(file)), path_(std::move(path)) {}

  // Parses a whole file; syntax errors name the file, line and column.
  static nlohmann::json parse_file(const std::filesystem::path& file);

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] const nlohmann::json& json() const { return *j_; }
  [[nodiscard]] bool has(const std::string& key) const { return j_->is_object() && j_->contains(key); }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  [[noreturn]] void fail_here(const std::string& what) const;

  // Child object or array element, for nested reading.
  JsonReader child(const std::string& key);
  JsonReader element(std::size_t index) const;
  [[nodiscard]] std::size_t array_size() const;

  // Typed values. Missing keys give the default; present keys must have the right type and range.
  double number(const std::string& key, double def, double min = -HUGE_VAL, double max = HUGE_VAL);
  double required_number(const std::string& key, double min = -HUGE_VAL, double max = HUGE_VAL);
  long integer(const std::string& key, long def, long min, long max);
  bool boolean(const std::string& key, bool def);
  std::string string(const std::string& key, const std::string& def);
  // One of a fixed set of words.
  std::string choice(const std::string& key, const std::string& def, const std::vector<std::string>& allowed);
  // A vector of exactly `dim` numbers (or any of `sizes` if given).
  std::vector<double> vector(const std::string& key, std::size_t dim, std::vector<double> def);
  std::vector<double> required_vector(const std::string& key, std::size_t dim);

  // Throws on keys of this object that were never read.
  void finish() const;

 private:
  const nlohmann::json& at(const std::string& key);
  std::string key_path(const std::string& key) const { return path_ + "/" + key; }

  const nlohmann::json* j_;
  std::string file_;
  std::string path_;
  std::set<std::string> read_;
};

std::string json_value_text(const nlohmann::json& v);

}  // namespace cellsph
