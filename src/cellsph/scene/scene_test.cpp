#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

const char* kMinimal = R"({
  "name": "t", "dimension": 2, "spacing": 0.1,
  "fluids": [{"min": [0, 0], "max": [1, 0.5]}],
  "boundary": {"box": {"min": [0, 0], "max": [2, 2]}}
})";

nlohmann::json with(const char* base, const std::string& pointer, const nlohmann::json& value) {
  auto j = nlohmann::json::parse(base);
  j[nlohmann::json::json_pointer(pointer)] = value;
  return j;
}

// Loads and returns the error message ("" when the scene is valid).
std::string load_error(const nlohmann::json& j, const std::string& source = "scene.json") {
  try {
    const auto h = read_scene_header(j, source);
    if (h.dim == 2)
      load_scene<2, double>(j, source);
    else
      load_scene<3, double>(j, source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, EveryBuiltinSceneLoads) {
  ASSERT_FALSE(builtin_scenes().empty());
  for (const auto& s : builtin_scenes()) {
    std::string src;
    const auto j = read_scene_json(std::string(s.name), src);
    EXPECT_EQ(load_error(j, src), "") << s.name;  // src: meshes/FILE is a built-in scene's mesh
    const auto h = read_scene_header(j, src);
    EXPECT_EQ(h.name, s.name) << "a built-in scene's name must match its file name";
    EXPECT_FALSE(h.description.empty()) << s.name;
  }
}

// A 3D tank with gravity along -y: open_top must open the y face and keep the z faces closed (it once
// opened the z-max face, so the 3D dam break drained through its front wall).
TEST(Scene, OpenTopWallsOpenTheFaceGravityPointsAwayFrom) {
  const auto j = nlohmann::json::parse(R"({
    "dimension": 3, "spacing": 0.1, "solver": {"gravity": [0, -9.81, 0]},
    "fluids": [{"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]}],
    "boundary": {"walls": {"min": [0, 0, 0], "max": [1, 1, 1], "layers": 1, "open_top": true}}
  })");
  const auto s = load_scene<3, double>(j, "scene.json");
  int above_y = 0, beyond_z = 0;
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    if (s.particles.kind[i] == 0) continue;
    above_y += s.particles.x[i][1] > 1 ? 1 : 0;
    beyond_z += s.particles.x[i][2] > 1 ? 1 : 0;
  }
  EXPECT_EQ(above_y, 0);
  EXPECT_EQ(beyond_z, 12 * 11);  // the z = 1.05 face: x in -0.05..1.05 (12), y in -0.05..0.95 (11)
}

// The Verlet skin defaults to 0.15 h, and to 0 under DFSPH (whose CFL steps outrun it); a scene's own
// neighbors.skin wins either way.
TEST(Scene, SkinDefaultsToZeroUnderDfsphOnly) {
  auto skin = [](const nlohmann::json& j) {
    return load_scene<2, double>(j, "scene.json").solver.verlet_skin;
  };
  EXPECT_DOUBLE_EQ(skin(nlohmann::json::parse(kMinimal)), 0.15);
  EXPECT_DOUBLE_EQ(skin(with(kMinimal, "/solver/model", "wcsph")), 0.15);
  const auto dfsph = with(kMinimal, "/solver/model", "dfsph");
  EXPECT_DOUBLE_EQ(skin(dfsph), 0.0);
  auto j = dfsph;
  j["neighbors"]["skin"] = 0.3;
  EXPECT_DOUBLE_EQ(skin(j), 0.3);
  EXPECT_DOUBLE_EQ(skin(with(kMinimal, "/neighbors/skin", 0.25)), 0.25);
}

TEST(Scene, BlockIsFilledAtLatticeCentresWithPhaseMass) {
  const auto j = nlohmann::json::parse(kMinimal);
  const auto s = load_scene<2, double>(j, "scene.json");
  // 10 x 5 particles at cell centres of a 0.1 lattice.
  ASSERT_EQ(s.particles.size(), 50u);
  EXPECT_DOUBLE_EQ(s.particles.x[0][0], 0.05);
  EXPECT_DOUBLE_EQ(s.particles.x[0][1], 0.05);
  EXPECT_NEAR(s.solver.phases[0].mass, 1000 * 0.1 * 0.1, 1e-12);  // rest density x spacing^2
  EXPECT_NEAR(s.solver.support, 0.2, 1e-15);                      // default: 2 spacings
  EXPECT_TRUE(s.solver.box.enabled);
}

// A scene with neither /domain nor a box gets one: its particles' starting bounding box grown by its
// longest side (here 10 spacings, 1 m, the larger) on every side. Water with nothing under it falls out of
// it and the run stops, saying so, once the lowest particle is a support below it (y = 0.05 - 1.2 m:
// after sqrt(2 x 1.2 / 9.81) = 0.49 s of free fall) instead of falling for ever.
TEST(Scene, WithoutADomainParticlesInFreeFlightStopTheRun) {
  auto j = nlohmann::json::parse(kMinimal);
  EXPECT_FALSE((load_scene<2, double>(j, "scene.json").solver.domain_set));  // the box bounds it
  j.erase("boundary");
  auto s = load_scene<2, double>(j, "scene.json");
  ASSERT_TRUE(s.solver.domain_default);
  EXPECT_DOUBLE_EQ(s.solver.domain_lo[0], 0.05 - 1);
  EXPECT_DOUBLE_EQ(s.solver.domain_lo[1], 0.05 - 1);
  EXPECT_DOUBLE_EQ(s.solver.domain_hi[0], 0.95 + 1);
  EXPECT_DOUBLE_EQ(s.solver.domain_hi[1], 0.45 + 1);
  Simulation<2, double> sim(s.solver, std::move(s.particles));
  try {
    sim.run_until(2);
    FAIL() << "ran to " << sim.time() << " s";
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("left the domain"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sets no /domain"), std::string::npos) << msg;
    EXPECT_GT(sim.time(), 0.4) << msg;
    EXPECT_LT(sim.time(), 0.6) << msg;
  }
}

TEST(Scene, PlanesAreNormalisedAndPassThroughTheirPoint) {
  auto j = nlohmann::json::parse(kMinimal);
  j["boundary"]["planes"] = nlohmann::json::parse(R"([{"normal": [0, 2], "point": [0, 0.25]}])");
  const auto s = load_scene<2, double>(j, "scene.json");
  ASSERT_EQ(s.solver.planes.size(), 1u);
  EXPECT_DOUBLE_EQ(s.solver.planes[0].normal[1], 1.0);
  EXPECT_DOUBLE_EQ(s.solver.planes[0].offset, 0.25);
}

struct BadCase {
  const char* pointer;
  const char* value;
  const char* expect_path;  // the key path the message must name
  const char* expect_text;  // and a word of the reason / the value
};

class SceneErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(SceneErrors, NameFileKeyPathAndValue) {
  const auto& c = GetParam();
  const auto j = with(kMinimal, c.pointer, nlohmann::json::parse(c.value));
  const std::string msg = load_error(j);
  ASSERT_FALSE(msg.empty()) << "scene with " << c.pointer << " = " << c.value << " was accepted";
  EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find(c.expect_path), std::string::npos) << msg;
  EXPECT_NE(msg.find(c.expect_text), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Scene, SceneErrors,
    ::testing::Values(
        BadCase{"/spacng", "0.1", "/spacng", "unknown key"},
        BadCase{"/spacing", "\"big\"", "/spacing", "\"big\""},
        BadCase{"/spacing", "-1", "/spacing", "out of range"},
        BadCase{"/dimension", "4", "/dimension", "out of range"},
        BadCase{"/precision", "\"half\"", "/precision", "half"},
        BadCase{"/fluids/0/max", "[1]", "/fluids/0/max", "array of 2"},
        BadCase{"/fluids/0/max", "[0.04, 0.5]", "/fluids/0/max", "no particle"},
        BadCase{"/fluids/0/min", "[1, 0]", "/fluids/0/max", "must exceed min"},
        BadCase{"/fluids/1", R"({"min": [0.5, 0], "max": [1.5, 0.5]})", "/fluids/1",
                "overlaps fluid block 0"},
        BadCase{"/fluids/0/phase", "3", "/fluids/0/phase", "out of range"},
        BadCase{"/fluids/0/phase", "\"oil\"", "/fluids/0/phase", "oil"},
        BadCase{"/fluids/0/max", "[3, 0.5]", "/fluids/0", "outside the boundary box"},
        BadCase{"/solver/support", "0.05", "/solver/support", "smaller than the particle spacing"},
        BadCase{"/solver/model", "\"pbf\"", "/solver/model", "pbf"},
        BadCase{"/solver/eos/kind", "\"ideal\"", "/solver/eos/kind", "ideal"},
        BadCase{"/solver/gravity", "[0, \"down\"]", "/solver/gravity", "down"},
        BadCase{"/solver/gravity", "[0, -1e300]", "/solver/gravity", "beyond 1e9"},
        BadCase{"/neighbors/method", "\"octree\"", "/neighbors/method", "octree"},
        BadCase{"/neighbors/subdivision", "0", "/neighbors/subdivision", "out of range"},
        BadCase{"/neighbors/skin", "-0.1", "/neighbors/skin", "out of range"},
        BadCase{"/neighbors/hash_table_size", "4294967295", "/neighbors/hash_table_size", "out of range"},
        BadCase{"/time/dt", "0", "/time/dt", "out of range"},
        BadCase{"/output/formats", "[\"obj\"]", "/output/formats/0", "obj"},
        BadCase{"/boundary/box/damping", "0.5", "/boundary/box/damping", "out of range"},
        BadCase{"/boundary/slip", "\"sticky\"", "/boundary/slip", "sticky"},
        BadCase{"/boundary/model", "\"ghost\"", "/boundary/model", "ghost"},
        BadCase{"/phases", "[]", "/phases", "at least one phase"},
        BadCase{"/phases/0", R"({"rest_density": -5})", "/phases/0/rest_density", "-5"}));

TEST(Scene, MissingFileIsAnInputError) {
  std::string src;
  EXPECT_THROW(read_scene_json("/nonexistent/scene.json", src), InputError);
}

TEST(Scene, SyntaxErrorNamesFileLineAndColumn) {
  const auto path = std::filesystem::temp_directory_path() / "cellsph_scene_syntax.json";
  { std::ofstream(path) << "{\n  \"name\": \"x\",\n  \"spacing\": 0.1,,\n}\n"; }
  std::string src;
  try {
    read_scene_json(path.string(), src);
    FAIL() << "invalid JSON accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ":3:"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

// nlohmann's operator[] fills an array up to the index an edit names: /phases/100000000/viscosity=1 once
// made 10^8 JSON values (1.6 GB) before the strict reader could refuse the scene (found by
// fuzz/scene_fuzz.cpp, input fuzz/regressions/scene/huge-array-index-in-set). An index may be at most one
// past the end (it appends, as "-" does), also in an array the edit creates.
TEST(Scene, EditsCannotGrowAnArrayByMoreThanOne) {
  const std::pair<std::string, std::string> refused[] = {
      {"/phases/100000000/viscosity=1",
       "index 100000000 is beyond the end of /phases (1 elements: the next is 1 or -)"},
      {"/fluids/2/min=[0,0]", "index 2 is beyond the end of /fluids (1 elements: the next is 1 or -)"},
      {"/extra/5=1", "index 5 is beyond the end of /extra (0 elements: the next is 0 or -)"},
      {"/fluids/0/min/44444444444=1", "index 44444444444 is beyond the end of /fluids/0/min (2 elements"}};
  for (const auto& [edit, what] : refused) {
    auto j = nlohmann::json::parse(kMinimal);
    j["phases"] = nlohmann::json::parse(R"([{"name": "water"}])");
    std::string src = "scene.json";
    try {
      apply_scene_edits(j, {edit}, src);
      FAIL() << "accepted " << edit;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--set '" + edit + "': " + what), std::string::npos) << e.what();
    }
  }
  auto j = nlohmann::json::parse(kMinimal);
  std::string src = "scene.json";
  apply_scene_edits(j, {"/fluids/1={\"min\": [1.2, 0], \"max\": [1.6, 0.4]}", "/extra/0=1"}, src);
  EXPECT_EQ(j["fluids"].size(), 2u);
  EXPECT_EQ(j["extra"], nlohmann::json::parse("[1]"));
}

// A number beyond a double is valid JSON text that the parser cannot hold: it once ended in "internal
// error" (nlohmann's out_of_range 406, not a parse_error); found by fuzz/scene_fuzz.cpp, input
// fuzz/regressions/scene/number-beyond-double.
TEST(Scene, NumberBeyondADoubleNamesFileLineAndColumn) {
  const auto path = std::filesystem::temp_directory_path() / "cellsph_scene_overflow.json";
  { std::ofstream(path) << "{\n  \"name\": \"x\",\n  \"spacing\": 1e400\n}\n"; }
  std::string src;
  try {
    read_scene_json(path.string(), src);
    FAIL() << "1e400 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ":3:14: invalid JSON (number 1e400 is beyond the range of a double)");
  }
  std::filesystem::remove(path);
}

// --set edits: numbers, arrays and bare words land at their pointer; the edited scene loads.
TEST(Scene, EditsSetValuesAtTheirPointers) {
  auto j = nlohmann::json::parse(kMinimal);
  std::string src = "scene.json";
  apply_scene_edits(j, {"/spacing=0.05", "/boundary/box/max=[3, 2]", "/name=edited", "/time/end=0.5"}, src);
  EXPECT_EQ(j["spacing"], 0.05);
  EXPECT_EQ(j["boundary"]["box"]["max"], nlohmann::json::parse("[3, 2]"));
  EXPECT_EQ(j["name"], "edited") << "a value that is not JSON is taken as a string";
  EXPECT_EQ(j["time"]["end"], 0.5) << "missing objects on the way are created";
  EXPECT_NE(src.find("scene.json (edited: /spacing=0.05"), std::string::npos) << src;
  EXPECT_EQ(load_error(j), "");
  const auto scene = load_scene<2, double>(j, src);
  // 1 m x 0.5 m at 0.05 m: 20 x 10 fluid particles (50 at the file's 0.1 m).
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < scene.particles.size(); ++i)
    fluid += scene.particles.kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid) ? 1 : 0;
  EXPECT_EQ(fluid, 200u);
}

// null removes a key (or an array element): how a scene drops a block another model refuses.
TEST(Scene, NullEditRemovesTheKey) {
  auto j = nlohmann::json::parse(kMinimal);
  std::string src = "scene.json";
  j["solver"]["note"] = 1;
  j["list"] = nlohmann::json::parse("[1, 2, 3]");
  apply_scene_edits(j, {"/solver/note=null", "/list/1=null"}, src);
  EXPECT_FALSE(j["solver"].contains("note"));
  EXPECT_EQ(j["list"], nlohmann::json::parse("[1, 3]"));
  try {
    apply_scene_edits(j, {"/solver/nothing=null"}, src);
    FAIL() << "removed a key that is not there";
  } catch (const InputError& ex) {
    EXPECT_EQ(std::string(ex.what()), "--set '/solver/nothing=null': /solver/nothing is not in the scene");
  }
}

TEST(Scene, BadEditsNameTheEdit) {
  for (const std::string e : {"spacing=0.1", "/spacing", "/=1", "/spacing=", "/fluids/x/min=1"}) {
    auto j = nlohmann::json::parse(kMinimal);
    std::string src = "scene.json";
    try {
      apply_scene_edits(j, {e}, src);
      FAIL() << "accepted '" << e << "'";
    } catch (const InputError& ex) {
      EXPECT_NE(std::string(ex.what()).find("--set '" + e + "'"), std::string::npos) << ex.what();
    }
  }
  // A misspelt key is accepted by the edit and rejected by the strict reader, with its path.
  auto j = nlohmann::json::parse(kMinimal);
  std::string src = "scene.json";
  apply_scene_edits(j, {"/spacng=0.05"}, src);
  const std::string err = load_error(j);
  EXPECT_NE(err.find("/spacng"), std::string::npos) << err;
}

// A --set value that is not JSON is taken as a string, and a JSON string must be UTF-8: a value with other
// bytes once passed the edit and ended in "internal error" where it was printed or saved to run.json
// (found by fuzz/scene_fuzz.cpp; the input is fuzz/regressions/scene/invalid-utf8-in-set-value). The
// invalid sequences are the standard ones: a stray 0xFF, an overlong '/', a UTF-16 surrogate, a 2-byte
// lead at the end.
TEST(Scene, EditsThatAreNotUtf8AreRefusedWithTheOffset) {
  const std::pair<std::string, std::string> cases[] = {
      {"/description=\xff", "byte 0xFF at offset 13"},
      {"/description=a\xc0\xaf", "byte 0xC0 at offset 14"},
      {"/neighbors={\"method\":\"\xed\xa0\x80\"}", "byte 0xED at offset 22"},
      {"/name=x\xc3", "byte 0xC3 at offset 7"}};
  for (const auto& [edit, where] : cases) {
    auto j = nlohmann::json::parse(kMinimal);
    std::string src = "scene.json";
    try {
      apply_scene_edits(j, {edit}, src);
      FAIL() << "accepted " << edit;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is not valid UTF-8 (" + where + ")"), std::string::npos)
          << e.what();
    }
  }
  // Well-formed UTF-8 of 2, 3 and 4 bytes is a string like any other.
  auto j = nlohmann::json::parse(kMinimal);
  std::string src = "scene.json";
  apply_scene_edits(j, {"/description=caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x8c\x8a"}, src);
  EXPECT_EQ(j["description"], "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x8c\x8a");
  EXPECT_EQ(load_error(j), "");
}

// A spacing far too fine stops before any particle is made, naming the object that goes over and the
// count (3e12 fluid particles: more than 2^31 on any machine), instead of allocating for hours.
TEST(Scene, TooManyParticlesIsAnInputErrorBeforeAnyIsMade) {
  std::string src;
  auto j = read_scene_json("dam-break-2d", src);
  apply_scene_edits(j, {"/spacing=1e-6", "/solver/support=2e-6"}, src);
  try {
    load_scene<2, double>(j, src);
    FAIL() << "2e12 particles accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("particles, more than"), std::string::npos) << m;
    EXPECT_NE(m.find("use a larger /spacing"), std::string::npos) << m;
    EXPECT_NE(m.find("/fluids: with the fluid blocks at spacing 1e-06 m the scene has 2e+12 particles"),
              std::string::npos)
        << m;
  }
  // The same in 3D (2.5e11 fluid particles at 0.2 mm).
  j = read_scene_json("dam-break-3d", src);
  apply_scene_edits(j, {"/spacing=2e-4", "/solver/support=4e-4"}, src);
  EXPECT_THROW((load_scene<3, float>(j, src)), InputError);
}

// SceneLimits::memory_bytes replaces the machine's memory in the count (the fuzz harness loads scenes on a
// budget of a few MiB). kMinimal makes 10 x 5 = 50 particles; with the default support (2 spacings) and
// skin (0.15) each has pi 2.3^2 = 16.6 pairs, 256 + 8 x 16.6 = 389 bytes by the cost model of
// docs/scenes.md: 50 particles fit in 60 x 389 bytes, not in 40 x 389.
TEST(Scene, MemoryLimitCapsTheParticles) {
  const auto j = nlohmann::json::parse(kMinimal);
  SceneLimits roomy, tight;
  roomy.memory_bytes = 60 * 389;
  tight.memory_bytes = 40 * 389;
  EXPECT_EQ((load_scene<2, double>(j, "scene.json", roomy).particles.size()), 50u);
  try {
    load_scene<2, double>(j, "scene.json", tight);
    FAIL() << "50 particles accepted in the memory of 40";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(
        m.find("scene.json: /fluids: with the fluid blocks at spacing 0.1 m the scene has 50 particles, "
               "more than 40 (what the allowed "),
        std::string::npos)
        << m;
  }
}

}  // namespace
}  // namespace cellsph
