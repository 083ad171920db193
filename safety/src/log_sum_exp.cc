#include "stewart/safety/log_sum_exp.h"

#include <cmath>

namespace stewart::safety {

double ComposeLogSumExp(const double* alpha_h, int n, double k, double* weights) {
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

}  // namespace stewart::safety
