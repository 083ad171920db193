// Config overlays (docs/operations.md, "Config overlays"): keys replace the
// config's key by key, mappings merge, sequences are replaced whole, and a
// key the config does not have is an error naming it.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/truth_loader.h"

namespace stewart {
namespace {

// An overlay file for one test, removed at its end.
class OverlayFile {
 public:
  OverlayFile(const std::string& name, const std::string& text)
      : path_(::testing::TempDir() + "overlay_" + name + "_" + std::to_string(::getpid()) +
              ".yaml") {
    std::ofstream(path_) << text;
  }
  ~OverlayFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string ErrorOf(const std::string& overlay_text) {
  YAML::Node config = LoadYamlFile(DefaultConfigPath());
  try {
    ApplyConfigOverlay(YAML::Load(overlay_text), "test.yaml", &config);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ConfigOverlay, ReplacesTheGivenKeysAndKeepsTheRest) {
  const StackConfig base = LoadStackConfig(DefaultConfigPath());
  const OverlayFile overlay("merge", R"(
platform:
  mass_kg: 0.87
  com_m: [0.01, -0.005, 0.008]
  inertia_products_kgm2: [-1.0e-4, 2.0e-4, 0.0]
safety:
  velocity_limits:
    - {axis: z, upper: 0.008, alpha_v: 2.0}
)");
  const StackConfig c = LoadStackConfig(DefaultConfigPath(), {overlay.path()});
  EXPECT_EQ(c.platform.platform_mass_kg, 0.87);
  EXPECT_EQ(c.platform.platform_com_in_P_m, Vector3d(0.01, -0.005, 0.008));
  EXPECT_EQ(c.platform.platform_inertia_products_kgm2, Vector3d(-1.0e-4, 2.0e-4, 0.0));
  // The rest of the platform section and the other sections are the config's.
  EXPECT_EQ(c.platform.platform_inertia_kgm2, base.platform.platform_inertia_kgm2);
  EXPECT_EQ(c.platform.base_joints_in_B_m, base.platform.base_joints_in_B_m);
  EXPECT_EQ(c.safety.k_velocity, base.safety.k_velocity);
  EXPECT_EQ(c.lcm.channels.command_safe, base.lcm.channels.command_safe);
  // A sequence is replaced whole: one velocity limit left, not three.
  ASSERT_EQ(c.safety.velocity_limits.size(), 1u);
  EXPECT_EQ(c.safety.velocity_limits[0].upper, 0.008);
}

TEST(ConfigOverlay, AppliedInOrder) {
  const OverlayFile first("first", "platform: {mass_kg: 0.7, gravity_mps2: 9.8}\n");
  const OverlayFile second("second", "platform: {mass_kg: 0.9}\n");
  const StackConfig c = LoadStackConfig(DefaultConfigPath(), {first.path(), second.path()});
  EXPECT_EQ(c.platform.platform_mass_kg, 0.9);
  EXPECT_EQ(c.platform.gravity_mps2, 9.8);
}

TEST(ConfigOverlay, AnEmptyOverlayChangesNothing) {
  const OverlayFile empty("empty", "# nothing\n");
  const StackConfig c = LoadStackConfig(DefaultConfigPath(), {empty.path()});
  EXPECT_EQ(c.platform.platform_mass_kg,
            LoadStackConfig(DefaultConfigPath()).platform.platform_mass_kg);
}

TEST(ConfigOverlay, AnUnknownKeyIsAnErrorNamingIt) {
  const std::string e = ErrorOf("platform: {mass_kgg: 0.8}\n");
  EXPECT_NE(e.find("'platform.mass_kgg'"), std::string::npos) << e;
  EXPECT_NE(e.find("not a key of the config"), std::string::npos) << e;
  EXPECT_NE(e.find("test.yaml"), std::string::npos) << e;
  EXPECT_NE(ErrorOf("payload: {mass_kg: 0.2}\n").find("'payload'"), std::string::npos);
  EXPECT_NE(ErrorOf("safety: {leg_stroke: {margin: 0.01}}\n").find("'safety.leg_stroke.margin'"),
            std::string::npos);
}

TEST(ConfigOverlay, AValueWhereTheConfigHasASectionIsAnError) {
  EXPECT_NE(ErrorOf("platform: 0.8\n").find("the config has a section here"), std::string::npos);
  EXPECT_NE(ErrorOf("platform: {mass_kg: {value: 0.8}}\n").find("the config has a value here"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[1, 2]\n").find("not a mapping"), std::string::npos);
}

TEST(ConfigOverlay, TheMergedConfigIsValidated) {
  const OverlayFile overlay("bad_value", "platform: {mass_kg: -1.0}\n");
  try {
    LoadStackConfig(DefaultConfigPath(), {overlay.path()});
    ADD_FAILURE() << "negative mass accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "platform.mass_kg");
  }
}

TEST(ConfigOverlay, ATruthOverridesTheConfigFileNotItsOverlays) {
  // Overlays are what the stack believes (an identified platform), the truth
  // is the simulated plant: with both, the plant is the file plus the truth.
  const StackConfig base = LoadStackConfig(DefaultConfigPath());
  const OverlayFile overlay("truth_base", "platform: {mass_kg: 0.8}\nlegs: {rod_mass_kg: 0.05}\n");
  const OverlayFile truth("truth", "legs: {rod_mass_kg: 0.06}\n");
  const StackConfig c = LoadStackConfig(DefaultConfigPath(), {overlay.path()});
  EXPECT_EQ(c.platform.platform_mass_kg, 0.8);
  const PlantTruth t = LoadPlantTruth(c, truth.path());
  EXPECT_EQ(t.platform.platform_mass_kg, base.platform.platform_mass_kg);
  EXPECT_EQ(t.platform.leg.rod_mass_kg, 0.06);
  // Without a truth the plant is the model, overlays included.
  EXPECT_EQ(LoadPlantTruth(c, "").platform.platform_mass_kg, 0.8);
}

TEST(ConfigOverlay, InertiaProductsMustLeaveThePlatformPhysical) {
  const OverlayFile overlay("products", "platform: {inertia_products_kgm2: [0.0045, 0, 0]}\n");
  try {
    LoadStackConfig(DefaultConfigPath(), {overlay.path()});
    ADD_FAILURE() << "indefinite inertia tensor accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "platform.inertia_products_kgm2") << e.what();
  }
}

}  // namespace
}  // namespace stewart
