#pragma once
// Alpha-weighted Log-Sum-Exp composition (NOTES.md, paper eqs. 28, 33, 34):
//
//   h_c = -(1/k) ln sum_i exp(-k alpha_i h_i)
//   w_i = exp(-k (alpha_i h_i - h_c))              (sum to 1)
//
// evaluated shifted by m = min_i alpha_i h_i so nothing overflows:
//   s = sum_i exp(-k (alpha_i h_i - m)) in [1, N],  h_c = m - ln(s)/k.
// Hence  m - ln(N)/k <= h_c <= m.

namespace stewart::safety {

/// `alpha_h[i]` = alpha_i h_i for i < n, `k` > 0; n >= 1 (checked: throws
/// std::logic_error). Writes the weights w_i to `weights` and returns h_c.
/// Non-finite input gives a non-finite h_c (the caller rejects it).
double ComposeLogSumExp(const double* alpha_h, int n, double k, double* weights);

}  // namespace stewart::safety
