#include "stewart/safety/log_sum_exp.h"

#include <cmath>

#include "stewart/common/check.h"

namespace stewart::safety {
namespace {

// exp(x) rounds to 0 in double below ln(2^-1075) = -745.13.
constexpr double kExpUnderflow = -746.0;

}  // namespace

double ComposeLogSumExp(const double* alpha_h, int n, double k, double* weights) {
  STEWART_CHECK(n >= 1, "ComposeLogSumExp: needs at least one term");
  // A plain comparison, not std::fmin (a libm call here): a NaN entry then
  // either becomes m or is skipped, and either way reaches the sum below.
  double m = alpha_h[0];
  for (int i = 1; i < n; ++i) m = alpha_h[i] < m ? alpha_h[i] : m;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    // Skips the exp() calls whose value is known exactly: exp(0) = 1 for the
    // smallest term, 0 for terms far above it (the usual case with a sharp k:
    // one barrier dominates). NaN takes the exp() path and propagates.
    const double x = -k * (alpha_h[i] - m);
    weights[i] = x == 0.0 ? 1.0 : (x < kExpUnderflow ? 0.0 : std::exp(x));
    sum += weights[i];
  }
  // sum = 1 exactly when one term dominates: weights are final, ln(1) = 0.
  if (sum == 1.0) return m;
  for (int i = 0; i < n; ++i) weights[i] /= sum;
  return m - std::log(sum) / k;
}

}  // namespace stewart::safety
