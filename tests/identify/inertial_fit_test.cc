// The inertial fit on the in-process closed loop (plant_sim's plant with a
// payload truth, the EKF, the controller and the safety filter, on the
// identify scenario), and its answers to data it cannot use.
//
// The stack is given the payload's mass and CoM as a rough prior (as if
// weighed and placed by hand): with the config's platform it cannot carry the
// payload, the platform sinks onto its end stops (docs/hardware.md, "Identify
// the platform and its payload"). Its inertia stays the bare plate's. The fit
// never reads the prior (FitIgnoresThePlatformBodyOfTheModel).
#include "stewart/identify/inertial_fit.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/identify/overlay_writer.h"
#include "stewart/identify/platform_estimate.h"
#include "stewart/model/dynamics.h"
#include "stewart/stack/closed_loop.h"

namespace stewart::identify {
namespace {

// 0.25 kg at (0.05, -0.03, 0.02) m in {P}: +40 % mass, the CoM moved by
// 14 mm, 9 mm and 5 mm, products of inertia that the bare plate lacks.
constexpr const char* kPayloadTruth = R"(
platform:
  payload: {mass_kg: 0.25, position_m: [0.05, -0.03, 0.02]}
)";

const std::string kIdentifyOverlay =
    std::string(STEWART_SOURCE_DIR) + "/config/overlays/identify.yaml";

// The prior the stack runs with: the payload as weighed and placed by hand,
// 1 g heavy and 5 mm off in x and y (CoM 2 mm off the plant's, 11 % of its
// distance from {P}'s origin), the bare plate's inertia (9 % off).
std::string PriorOverlayPath() {
  static const std::string path = [] {
    Payload measured;
    measured.mass_kg = 0.251;
    measured.position_in_P_m = Vector3d(0.055, -0.025, 0.02);
    const PlatformParams prior =
        WithPayload(LoadStackConfig(DefaultConfigPath()).platform, measured);
    const Vector3d& c = prior.platform_com_in_P_m;
    char text[256];
    std::snprintf(text, sizeof text, "platform: {mass_kg: %.17g, com_m: [%.17g, %.17g, %.17g]}\n",
                  prior.platform_mass_kg, c.x(), c.y(), c.z());
    const std::string p =
        ::testing::TempDir() + "identify_prior_" + std::to_string(::getpid()) + ".yaml";
    std::ofstream(p) << text;
    return p;
  }();
  return path;
}

StackConfig IdentifyConfig() {
  return LoadStackConfig(DefaultConfigPath(), {kIdentifyOverlay, PriorOverlayPath()});
}

struct ClosedLoopRecord {
  std::vector<IdentificationSample> truth;     // true state, applied force
  std::vector<IdentificationSample> estimate;  // the EKF's state, applied force
  PlatformParams plant;                        // the truth's platform (with payload)
  ClosedLoopSummary summary;
};

// One run of the closed loop; samples from its per-tick CSV (17 digits).
ClosedLoopRecord RunIdentifyScenario(const StackConfig& config, unsigned seed) {
  ClosedLoopOptions options;
  options.seed = seed;
  // The truth overrides the config file, not the overlays (as launch.sh does).
  options.truth =
      ParsePlantTruth(config, LoadYamlFile(DefaultConfigPath()), YAML::Load(kPayloadTruth));
  const Scenario scenario = LoadScenario(ResolveScenarioPath("identify"));
  options.duration_s = scenario.duration_s();
  std::ostringstream csv;
  csv.precision(17);
  ClosedLoopRecord record;
  record.summary = RunClosedLoop(config, scenario, options, &csv);
  record.plant = options.truth->platform;
  std::istringstream lines(csv.str());
  std::string line;
  std::getline(lines, line);  // header: t, q_, qd_, qest_, qdest_, fdes_, fsafe_, ...
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(fields, field, ',')) v.push_back(std::stod(field));
    IdentificationSample truth;
    truth.utime = std::llround(v[0] * 1e6);
    for (int i = 0; i < 6; ++i) {
      truth.q(i) = v[1 + i];
      truth.qd(i) = v[7 + i];
      truth.force_n(i) = v[31 + i];
    }
    IdentificationSample estimate = truth;
    for (int i = 0; i < 6; ++i) {
      estimate.q(i) = v[13 + i];
      estimate.qd(i) = v[19 + i];
    }
    record.truth.push_back(truth);
    // The EKF settles in its first settle_samples; those estimates are not used.
    if (truth.utime >= 500000) record.estimate.push_back(estimate);
  }
  return record;
}

struct Errors {
  double mass;     // relative
  double com;      // |c - c_true| / |c_true|
  double inertia;  // Frobenius norm of the tensor difference, relative
};

Errors ErrorsOf(const PlatformEstimate& e, const PlatformParams& truth) {
  Errors err;
  err.mass = std::abs(e.body.mass_kg - truth.platform_mass_kg) / truth.platform_mass_kg;
  err.com =
      (e.body.com_in_P_m - truth.platform_com_in_P_m).norm() / truth.platform_com_in_P_m.norm();
  err.inertia = (e.body.inertia_about_com_in_P_kgm2 - PlatformInertiaInP(truth)).norm() /
                PlatformInertiaInP(truth).norm();
  return err;
}

std::string Describe(const Errors& err, const InertialFit& fit) {
  char text[256];
  std::snprintf(
      text, sizeof text, "mass %.3f %%, CoM %.3f %%, inertia %.3f %%; %ld windows, condition %.3g",
      100 * err.mass, 100 * err.com, 100 * err.inertia, fit.windows, fit.condition_number);
  return text;
}

class ClosedLoopFit : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    record_ = new ClosedLoopRecord(RunIdentifyScenario(IdentifyConfig(), 3));
  }
  static void TearDownTestSuite() {
    delete record_;
    std::remove(PriorOverlayPath().c_str());
  }
  static ClosedLoopRecord* record_;
};
ClosedLoopRecord* ClosedLoopFit::record_ = nullptr;

TEST_F(ClosedLoopFit, TheExcitationHoldsTheLimits) {
  const ClosedLoopSummary& s = record_->summary;
  ASSERT_TRUE(s.completed) << s.failure;
  std::printf("%s", FormatSummary(IdentifyConfig(), s).c_str());
  EXPECT_LE(s.max_limit_excess, 1e-3) << s.max_limit_excess_name;
  EXPECT_EQ(s.endstop_hits, 0);
}

TEST_F(ClosedLoopFit, RecoversThePayloadFromTheTrueState) {
  // With the true state only the discretisation (trapezoids at 1 kHz) is
  // between the data and the model.
  const StackConfig config = IdentifyConfig();
  const InertialFit fit = FitInertialParameters(
      config.platform, config.actuators.viscous_friction_nspm, record_->truth);
  const PlatformEstimate e = EstimatePlatform(fit);
  const Errors err = ErrorsOf(e, record_->plant);
  std::printf("true state: %s\n", Describe(err, fit).c_str());
  EXPECT_LT(err.mass, 0.002);
  EXPECT_LT(err.com, 0.01);
  EXPECT_LT(err.inertia, 0.01);
}

TEST_F(ClosedLoopFit, RecoversThePayloadFromTheEstimate) {
  const StackConfig config = IdentifyConfig();
  const InertialFit fit = FitInertialParameters(
      config.platform, config.actuators.viscous_friction_nspm, record_->estimate);
  const PlatformEstimate e = EstimatePlatform(fit);
  const Errors err = ErrorsOf(e, record_->plant);
  std::printf("estimate: %s\n", Describe(err, fit).c_str());
  EXPECT_LT(err.mass, 0.02);
  EXPECT_LT(err.com, 0.05);
  EXPECT_LT(err.inertia, 0.05);
  // The stated uncertainty is not wildly optimistic: the errors are within
  // four sigma of each value.
  const PlatformValues truth =
      PlatformValuesOf(PlatformBodyOf(InertialParametersOf(record_->plant)));
  for (int i = 0; i < 10; ++i) {
    EXPECT_LT(std::abs(e.values(i) - truth(i)), 4.0 * e.sigma(i) + 1e-12)
        << "value " << i << ": " << e.values(i) << " vs " << truth(i) << " sigma " << e.sigma(i);
  }
}

TEST_F(ClosedLoopFit, FitIgnoresThePlatformBodyOfTheModel) {
  // Only the legs, the geometry and gravity of the model enter the fit: the
  // config's platform (the config's, or the prior the stack ran with) gives
  // the same answer, bit for bit.
  const StackConfig config = IdentifyConfig();
  PlatformParams other = LoadStackConfig(DefaultConfigPath()).platform;
  other.platform_mass_kg = 5.0;
  other.platform_inertia_products_kgm2 = Vector3d(1e-4, 2e-4, 3e-4);
  const InertialFit a = FitInertialParameters(
      config.platform, config.actuators.viscous_friction_nspm, record_->estimate);
  const InertialFit b =
      FitInertialParameters(other, config.actuators.viscous_friction_nspm, record_->estimate);
  EXPECT_EQ(a.pi, b.pi);
}

TEST_F(ClosedLoopFit, TheOverlayLoadsAsTheIdentifiedPlatform) {
  const StackConfig config = IdentifyConfig();
  const InertialFit fit = FitInertialParameters(
      config.platform, config.actuators.viscous_friction_nspm, record_->truth);
  const PlatformEstimate e = EstimatePlatform(fit);
  const std::string path =
      ::testing::TempDir() + "identify_overlay_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << FormatPlatformOverlay(e, fit, "test");
  const StackConfig loaded = LoadStackConfig(DefaultConfigPath(), {kIdentifyOverlay, path});
  std::remove(path.c_str());
  EXPECT_NEAR(loaded.platform.platform_mass_kg, e.body.mass_kg, 1e-6 * e.body.mass_kg);
  EXPECT_LT((loaded.platform.platform_com_in_P_m - e.body.com_in_P_m).norm(), 1e-8);
  EXPECT_LT((PlatformInertiaInP(loaded.platform) - e.body.inertia_about_com_in_P_kgm2).norm(),
            1e-8);
  // Only the platform's mass properties changed.
  EXPECT_EQ(loaded.platform.leg.rod_mass_kg, config.platform.leg.rod_mass_kg);
  EXPECT_EQ(loaded.estimator.process_model, config.estimator.process_model);
}

// Data the fit cannot use gives one IdentificationError saying why.
std::string ErrorOf(const std::vector<IdentificationSample>& samples) {
  const PlatformParams model = LoadStackConfig(DefaultConfigPath()).platform;
  try {
    FitInertialParameters(model, 2.0, samples);
  } catch (const IdentificationError& e) {
    return e.what();
  }
  return "no error";
}

// The platform held still at home by its gravity-compensating forces.
std::vector<IdentificationSample> HoldingStill(double duration_s) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const DynamicsTerms t = EvaluateDynamics(config.platform, config.home_pose, Vector6d::Zero());
  const Vector6d holding = InverseDynamics(t, Vector6d::Zero());
  std::vector<IdentificationSample> samples;
  for (long k = 0; k < std::lround(duration_s * 1000); ++k) {
    samples.push_back({k * 1000, config.home_pose, Vector6d::Zero(), holding});
  }
  return samples;
}

TEST(InertialFitInput, NoSamples) { EXPECT_NE(ErrorOf({}).find("no samples"), std::string::npos); }

TEST(InertialFitInput, TooFewSamples) {
  const std::string e = ErrorOf(HoldingStill(1.0));
  EXPECT_NE(e.find("windows"), std::string::npos) << e;
  EXPECT_NE(e.find("at least"), std::string::npos) << e;
}

TEST(InertialFitInput, GapsSplitTheWindows) {
  // 10 s of samples, but a gap every 0.2 s: no window of 0.25 s.
  std::vector<IdentificationSample> samples = HoldingStill(10.0);
  for (std::size_t k = 0; k < samples.size(); ++k) samples[k].utime += (k / 200) * 10000;
  const std::string e = ErrorOf(samples);
  EXPECT_NE(e.find("give 0 windows"), std::string::npos) << e;
}

TEST(InertialFitInput, MotionlessDataIsSingular) {
  // At rest only gravity acts: mass and the horizontal CoM, nothing else.
  const std::string e = ErrorOf(HoldingStill(10.0));
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  EXPECT_NE(e.find("I_O"), std::string::npos) << e;
}

TEST(InertialFitInput, NonFiniteAndUnorderedSamples) {
  std::vector<IdentificationSample> samples = HoldingStill(10.0);
  samples[17].qd(4) = NAN;
  EXPECT_NE(ErrorOf(samples).find("sample 17"), std::string::npos);
  samples = HoldingStill(10.0);
  std::swap(samples[5].utime, samples[6].utime);
  EXPECT_NE(ErrorOf(samples).find("not in time order"), std::string::npos);
}

TEST(PlatformEstimateChecks, RejectsBodiesThatCannotExist) {
  InertialFit fit;
  fit.pi << -0.5, 0, 0, 0, 0.004, 0, 0, 0.004, 0, 0.008;
  try {
    EstimatePlatform(fit);
    ADD_FAILURE() << "negative mass accepted";
  } catch (const IdentificationError& e) {
    EXPECT_NE(std::string(e.what()).find("not positive"), std::string::npos) << e.what();
  }
  fit.pi << 0.8, 0, 0, 0, 0.004, 0, 0, -0.001, 0, 0.008;
  try {
    EstimatePlatform(fit);
    ADD_FAILURE() << "indefinite inertia accepted";
  } catch (const IdentificationError& e) {
    EXPECT_NE(std::string(e.what()).find("positive definite"), std::string::npos) << e.what();
  }
  fit.pi << 0.8, 0, 0, 0, 0.001, 0, 0, 0.001, 0, 0.008;
  try {
    EstimatePlatform(fit);
    ADD_FAILURE() << "triangle inequality violation accepted";
  } catch (const IdentificationError& e) {
    EXPECT_NE(std::string(e.what()).find("triangle"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace stewart::identify
