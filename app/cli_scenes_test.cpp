// `cellsph scenes` (cmd_scenes.cpp): a listing that fits a terminal, and one scene shown in full.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_test_util.hpp"

namespace {

using cellsph::test::run_cli;
using cellsph::test::TempDir;
namespace fs = std::filesystem;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::string file_text(const fs::path& p) {
  return cellsph::test::read_file(p);
}

// The JSON files of scenes/ (its folders hold meshes and examples that are not built in).
std::vector<fs::path> scene_files() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(cellsph::test::source_dir()) / "scenes"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  return files;
}

TEST(CliScenes, ListsEveryBuiltinSceneOnOneLineOfAtMost100Characters) {
  TempDir dir;
  const auto r = run_cli(dir, "scenes");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto lines = lines_of(r.out);
  for (const auto& l : lines) EXPECT_LE(l.size(), 100u) << l;
  for (const auto& f : scene_files()) {
    const std::string name = f.stem().string();
    const auto j = nlohmann::json::parse(file_text(f));
    const std::string model = j["solver"].value("model", "");
    // Its line starts with the name, then its dimension and, where the file names one, its model.
    int found = 0;
    for (const auto& l : lines) {
      if (l.rfind(name + " ", 0) != 0) {
        continue;
      }
      ++found;
      std::string dim = " ";
      dim += std::to_string(j["dimension"].get<int>());
      dim += "D ";
      EXPECT_NE(l.find(dim), std::string::npos) << l;
      if (!model.empty()) {
        EXPECT_NE(l.find(' ' + model + ' '), std::string::npos) << l;
      }
      EXPECT_NE(l.find(" particles "), std::string::npos) << l;
    }
    EXPECT_EQ(found, 1) << name;
  }
}

TEST(CliScenes, ShowsOneSceneInFull) {
  TempDir dir;
  const fs::path file = fs::path(cellsph::test::source_dir()) / "scenes" / "droplet.json";
  const std::string text = file_text(file);
  const auto r = run_cli(dir, "scenes droplet");
  ASSERT_EQ(r.code, 0) << r.err;
  // The file as written, after a header and the description (wrapped to 100 columns).
  ASSERT_GE(r.out.size(), text.size());
  EXPECT_EQ(r.out.substr(r.out.size() - text.size()), text);
  const std::string description = nlohmann::json::parse(text)["description"];
  std::string words = r.out.substr(0, r.out.size() - text.size());
  for (auto& c : words)
    if (c == '\n') c = ' ';
  EXPECT_NE(words.find(description), std::string::npos);
  for (const auto& l : lines_of(r.out.substr(0, r.out.size() - text.size()))) EXPECT_LE(l.size(), 100u) << l;

  // A scene file shows as well (its JSON, re-indented).
  const auto f = run_cli(dir, "scenes '" + file.string() + "'");
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_NE(f.out.find("\"name\": \"droplet\""), std::string::npos);
}

TEST(CliScenes, AnUnknownSceneIsAnInputError) {
  TempDir dir;
  const auto r = run_cli(dir, "scenes no-such-scene");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("'no-such-scene'"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace
