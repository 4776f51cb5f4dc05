#pragma once
// The built-in scenes: the JSON files of scenes/, compiled in by CMake.
#include <string_view>
#include <vector>

namespace cellsph {

struct BuiltinScene {
  std::string_view name;  // file name without .json
  std::string_view json;  // the file's text
};

const std::vector<BuiltinScene>& builtin_scenes();

// The meshes of scenes/meshes/ (text formats), which built-in scenes name as "meshes/FILE".
struct BuiltinMesh {
  std::string_view name;  // "meshes/FILE"
  std::string_view data;  // the file's bytes
};

const std::vector<BuiltinMesh>& builtin_meshes();

}  // namespace cellsph
