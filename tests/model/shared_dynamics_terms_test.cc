// One evaluation of the model terms shared between components: a hit is the
// evaluation itself, bit for bit; other parameters are refused.
#include "stewart/model/shared_dynamics_terms.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "stewart/config/default_config.h"

namespace stewart {
namespace {

void ExpectBitIdentical(const DynamicsTerms& a, const DynamicsTerms& b) {
  EXPECT_TRUE(a.M == b.M);
  EXPECT_TRUE(a.C_qd == b.C_qd);
  EXPECT_TRUE(a.G == b.G);
  EXPECT_TRUE(a.H == b.H);
  EXPECT_TRUE(a.leg_length_m == b.leg_length_m);
}

Vector6d Pose() { return (Vector6d() << 0.02, -0.01, 0.44, 0.03, -0.02, 0.05).finished(); }
Vector6d Rate() { return (Vector6d() << 0.01, 0.0, -0.005, 0.1, 0.02, -0.04).finished(); }

TEST(SharedDynamicsTerms, AnswersTheSameStateFromOneEvaluation) {
  const PlatformParams& p = DefaultStackConfig().platform;
  SharedDynamicsTerms shared(p);
  DynamicsTerms first, second, own;
  shared.Evaluate(Pose(), Rate(), &first);
  shared.Evaluate(Pose(), Rate(), &second);
  EvaluateDynamics(p, Pose(), Rate(), &own);
  EXPECT_EQ(shared.evaluations(), 1);
  EXPECT_EQ(shared.hits(), 1);
  ExpectBitIdentical(first, own);
  ExpectBitIdentical(second, own);
}

TEST(SharedDynamicsTerms, EvaluatesAnyOtherStateAnew) {
  const PlatformParams& p = DefaultStackConfig().platform;
  SharedDynamicsTerms shared(p);
  DynamicsTerms a, b, own;
  shared.Evaluate(Pose(), Rate(), &a);
  Vector6d qd = Rate();
  qd(5) = std::nextafter(qd(5), 1.0);  // one ulp away is another state
  shared.Evaluate(Pose(), qd, &b);
  EvaluateDynamics(p, Pose(), qd, &own);
  EXPECT_EQ(shared.evaluations(), 2);
  EXPECT_EQ(shared.hits(), 0);
  ExpectBitIdentical(b, own);
}

TEST(SharedDynamicsTerms, NeverAnswersANonFiniteStateFromTheCache) {
  const PlatformParams& p = DefaultStackConfig().platform;
  SharedDynamicsTerms shared(p);
  Vector6d q = Pose();
  q(0) = NAN;
  DynamicsTerms t;
  shared.Evaluate(q, Rate(), &t);
  shared.Evaluate(q, Rate(), &t);
  EXPECT_EQ(shared.evaluations(), 2);
  EXPECT_EQ(shared.hits(), 0);
}

TEST(SharedDynamicsTerms, RefusesAComponentWithOtherParameters) {
  const PlatformParams& p = DefaultStackConfig().platform;
  auto shared = std::make_shared<SharedDynamicsTerms>(p);
  EXPECT_EQ(AttachSharedTerms(p, shared), shared);
  EXPECT_EQ(AttachSharedTerms(p, nullptr), nullptr);
  PlatformParams heavier = p;
  heavier.platform_mass_kg *= 1.05;
  EXPECT_THROW(AttachSharedTerms(heavier, shared), std::invalid_argument);
  PlatformParams rotor = p;
  rotor.leg.actuator_reflected_mass_kg += 1.0;
  EXPECT_THROW(AttachSharedTerms(rotor, shared), std::invalid_argument);
  PlatformParams joint = p;
  joint.platform_joints_in_P_m(1, 4) += 1e-6;
  EXPECT_THROW(AttachSharedTerms(joint, shared), std::invalid_argument);
  EXPECT_TRUE(SameParams(p, PlatformParams(p)));
  EXPECT_FALSE(SameParams(p, joint));
}

}  // namespace
}  // namespace stewart
