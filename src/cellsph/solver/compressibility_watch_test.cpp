// The compressibility watch: each warning once, at its threshold, naming the phase and the key that fixes
// it; nothing for the implicit models, nothing for a free surface's density deficit.
#include "cellsph/solver/compressibility_watch.hpp"

#include <gtest/gtest.h>

#include <string>

namespace cellsph {
namespace {

// Ten water particles at rest density, at rest, plus one wall particle compressed 50% (walls are not
// fluid: never counted). Ratio state equation with k = 1e5 Pa: c = 10 m/s.
struct WaterAtRest {
  SolverConfig<2, double> cfg;
  Particles<2, double> p;
  WaterAtRest() {
    cfg.eos.kind = EosKind::Ratio;
    cfg.eos.stiffness = 1e5;
    p.resize(11);
    for (std::size_t i = 0; i < 11; ++i) {
      p.rho[i] = 1000;
      p.phase[i] = 0;
      p.kind[i] = std::uint8_t(i < 10 ? ParticleKind::Fluid : ParticleKind::Boundary);
    }
    p.rho[10] = 1500;
    p.v[10] = {100, 0};
  }
};

bool has(const std::vector<std::string>& w, const std::string& text) {
  for (const auto& s : w)
    if (s.find(text) != std::string::npos) return true;
  return false;
}

TEST(CompressibilityWatch, QuietAtRestAndUnderAFreeSurfacesDeficit) {
  WaterAtRest s;
  CompressibilityWatch<2, double> watch;
  EXPECT_TRUE(watch.check(s.cfg, s.p, 0).empty());
  for (std::size_t i = 0; i < 10; ++i) s.p.rho[i] = 600;  // 40% below rest: a splash, no compression
  EXPECT_TRUE(watch.check(s.cfg, s.p, 0.1).empty());
}

TEST(CompressibilityWatch, EachWarningOnceAtItsThreshold) {
  WaterAtRest s;
  CompressibilityWatch<2, double> watch;
  // One particle 2.9% above rest: the largest is under 3%, the mean 0.29%.
  s.p.rho[0] = 1029;
  EXPECT_TRUE(watch.check(s.cfg, s.p, 0.1).empty());
  // 3.1%: the largest passes 3%; the mean (0.31%) stays under 1%.
  s.p.rho[0] = 1031;
  auto w = watch.check(s.cfg, s.p, 0.2);
  ASSERT_EQ(w.size(), 1U);
  EXPECT_TRUE(has(w, "t = 0.2 s: phase 0 (water): largest density 3.1% above rest (over 3%)")) << w[0];
  EXPECT_TRUE(has(w, "raise /solver/eos/stiffness (now 1e+05, speed of sound 10 m/s)")) << w[0];
  // Every particle 1.1% above rest: the mean passes 1%; the largest was said already.
  for (std::size_t i = 0; i < 10; ++i) s.p.rho[i] = 1011;
  s.p.rho[0] = 1050;
  w = watch.check(s.cfg, s.p, 0.3);
  ASSERT_EQ(w.size(), 1U);
  EXPECT_TRUE(has(w, "mean density 1.5% above rest (over 1%)")) << w[0];
  // 0.9 m/s is Mach 0.09, 1.1 m/s Mach 0.11.
  s.p.v[3] = {0, 0.9};
  EXPECT_TRUE(watch.check(s.cfg, s.p, 0.4).empty());
  s.p.v[3] = {0, -1.1};
  w = watch.check(s.cfg, s.p, 0.5);
  ASSERT_EQ(w.size(), 1U);
  EXPECT_TRUE(has(w, "Mach number 0.11 (fastest particle 1.1 m/s; over 0.1)")) << w[0];
  EXPECT_TRUE(watch.check(s.cfg, s.p, 0.6).empty());
  EXPECT_EQ(watch.given().size(), 3U);
}

TEST(CompressibilityWatch, TheImplicitModelsBoundTheirOwnError) {
  for (const Model m : {Model::Dfsph, Model::Iisph}) {
    WaterAtRest s;
    s.cfg.model = m;
    for (std::size_t i = 0; i < 10; ++i) s.p.rho[i] = 1100;
    CompressibilityWatch<2, double> watch;
    EXPECT_TRUE(watch.check(s.cfg, s.p, 0).empty());
  }
}

}  // namespace
}  // namespace cellsph
