#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "stewart/safety/log_sum_exp.h"

namespace stewart::safety {
namespace {

TEST(LogSumExp, BoundsHoldForRandomInputs) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> value(-1.0, 1.0), logk(0.0, 6.0);
  std::uniform_int_distribution<int> count(1, 24);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = count(rng);
    const double k = std::pow(10.0, logk(rng));
    std::array<double, 24> ah{}, w{};
    for (int i = 0; i < n; ++i) ah[static_cast<size_t>(i)] = value(rng);
    const double h_c = ComposeLogSumExp(ah.data(), n, k, w.data());
    const double m = *std::min_element(ah.begin(), ah.begin() + n);
    EXPECT_LE(h_c, m + 1e-15);
    EXPECT_GE(h_c, m - std::log(n) / k - 1e-15);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += w[static_cast<size_t>(i)];
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
}

TEST(LogSumExp, GradientEqualsFiniteDifferences) {
  // dh_c / d(alpha_i h_i) = w_i.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> value(-0.01, 0.01);
  for (double k : {1.0, 1e2, 1e4}) {
    std::array<double, 8> ah{}, w{}, w_unused{};
    for (double& v : ah) v = value(rng);
    ComposeLogSumExp(ah.data(), 8, k, w.data());
    for (size_t i = 0; i < 8; ++i) {
      const double eps = 1e-7 / k;
      std::array<double, 8> plus = ah, minus = ah;
      plus[i] += eps;
      minus[i] -= eps;
      const double fd = (ComposeLogSumExp(plus.data(), 8, k, w_unused.data()) -
                         ComposeLogSumExp(minus.data(), 8, k, w_unused.data())) /
                        (2 * eps);
      EXPECT_NEAR(fd, w[i], 1e-6) << "k " << k << " i " << i;
    }
  }
}

TEST(LogSumExp, StableForHugeSharpness) {
  // exp(-k h) would overflow (k h = -1e10) or underflow without the shift.
  const std::array<double, 3> ah = {-1.0, 0.5, 2.0};
  std::array<double, 3> w{};
  const double h_c = ComposeLogSumExp(ah.data(), 3, 1e10, w.data());
  EXPECT_TRUE(std::isfinite(h_c));
  EXPECT_DOUBLE_EQ(h_c, -1.0);
  EXPECT_DOUBLE_EQ(w[0], 1.0);
  EXPECT_EQ(w[1], 0.0);
}

TEST(LogSumExp, EqualInputsLoseExactlyLnNOverK) {
  const std::array<double, 4> ah = {0.3, 0.3, 0.3, 0.3};
  std::array<double, 4> w{};
  EXPECT_NEAR(ComposeLogSumExp(ah.data(), 4, 10.0, w.data()), 0.3 - std::log(4.0) / 10.0, 1e-15);
  EXPECT_NEAR(w[2], 0.25, 1e-15);
}

// The composition as written in the header, every exp() and log() called.
double PlainLogSumExp(const double* alpha_h, int n, double k, double* weights) {
  double m = alpha_h[0];
  for (int i = 1; i < n; ++i) m = std::fmin(m, alpha_h[i]);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    weights[i] = std::exp(-k * (alpha_h[i] - m));
    sum += weights[i];
  }
  for (int i = 0; i < n; ++i) weights[i] /= sum;
  return m - std::log(sum) / k;
}

TEST(LogSumExp, SkippedCallsGiveTheSameNumbers) {
  // ComposeLogSumExp leaves out exp(0), the exp() that underflow to 0 and
  // log(1): bit for bit the plain evaluation, for sharp and mild k.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-0.05, 0.05), logk(0.0, 7.0);
  std::uniform_int_distribution<int> count(1, 15);
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = count(rng);
    const double k = std::pow(10.0, logk(rng));
    std::array<double, 15> ah{}, w{}, w_plain{};
    for (int i = 0; i < n; ++i) ah[static_cast<size_t>(i)] = value(rng);
    if (trial % 3 == 0) ah[static_cast<size_t>(n - 1)] = ah[0];  // ties at the minimum
    const double h_c = ComposeLogSumExp(ah.data(), n, k, w.data());
    const double h_plain = PlainLogSumExp(ah.data(), n, k, w_plain.data());
    ASSERT_EQ(h_c, h_plain) << "trial " << trial;
    for (int i = 0; i < n; ++i) {
      ASSERT_EQ(w[static_cast<size_t>(i)], w_plain[static_cast<size_t>(i)]) << "trial " << trial;
    }
  }
}

TEST(LogSumExp, NanPropagatesToBeRejected) {
  const std::array<double, 2> ah = {0.3, NAN};
  std::array<double, 2> w{};
  EXPECT_FALSE(std::isfinite(ComposeLogSumExp(ah.data(), 2, 10.0, w.data())));
}

}  // namespace
}  // namespace stewart::safety
