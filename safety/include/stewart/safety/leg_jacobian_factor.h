#pragma once
// The leg Jacobian H's LU factor for the solves of one filter step.
#include "stewart/model/linear_algebra6.h"

namespace stewart::safety {

/// H's LU factor (H: generalized force per leg force, q-space x legs),
/// factored by the first solve of a step that needs it. A step may solve
/// with H for the nominal's zero-acceleration force, the closed form's
/// correction and the metric map T = H^-1 L_M; each of them factored H.
/// Every solve between two Reset calls must pass the same H.
class LegJacobianFactor {
 public:
  /// Forgets the factor: the next solve factors its `h`.
  void Reset() { computed_ = false; }

  /// B := H^-1 B; false (B unusable) when H is singular or not finite.
  template <int Cols>
  bool Solve(const Matrix6d& h, Eigen::Matrix<double, 6, Cols>* b) {
    if (!computed_) {
      nonsingular_ = lu_.Compute(h);
      h_norm_ = h.norm();
      computed_ = true;
    }
    if (!nonsingular_) return false;
    lu_.SolveInPlace(b);
    return true;
  }

  /// ||H||_F of the factored H (valid after a Solve).
  double h_norm() const { return h_norm_; }

 private:
  PartialPivLu6 lu_;
  double h_norm_ = 0.0;
  bool computed_ = false;
  bool nonsingular_ = false;
};

}  // namespace stewart::safety
