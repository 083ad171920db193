#pragma once
// Leg kinematics of the 6-6 Stewart platform.
//
// Paper eq. 1:  l_i = t + R(r) p_i - b_i  (in {B}),  leg length L_i = |l_i|.
// Leg-length Jacobian J_l = dL/dq (6x6, row i = n_i^T [I, -[R p_i]x E(r)]),
// so Ld = J_l qd and, by virtual work, H = J_l^T.
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// Per-leg geometry at one pose (all in {B}).
struct LegGeometry {
  Eigen::Matrix<double, 3, kNumLegs> platform_offset_in_B_m;  ///< R p_i
  Eigen::Matrix<double, 3, kNumLegs> unit_in_B;               ///< n_i = l_i / L_i
  Vector6d length_m;                                          ///< L_i
};

/// Inverse kinematics at q = [x y z phi theta psi].
LegGeometry ComputeLegGeometry(const PlatformParams& params, const Vector6d& q);

/// Leg lengths L_i (m) at q (paper eq. 1).
Vector6d InverseKinematics(const PlatformParams& params, const Vector6d& q);

/// J_l = dL/dq (m/m and m/rad) from already computed leg geometry.
Matrix6d LegLengthJacobian(const LegGeometry& legs, const Vector3d& rpy_rad);
Matrix6d LegLengthJacobian(const PlatformParams& params, const Vector6d& q);

struct ForwardKinematicsResult {
  Vector6d q = Vector6d::Zero();
  bool converged = false;
  int iterations = 0;
  double residual_m = 0.0;  ///< max |L_i(q) - L_i measured| at the end
};

struct ForwardKinematicsOptions {
  int max_iterations = 20;
  double tolerance_m = 1e-12;
};

/// Newton's method on L(q) = leg_length_m from `q_guess`. Reports
/// non-convergence (and a non-finite or singular step) instead of throwing.
ForwardKinematicsResult ForwardKinematics(const PlatformParams& params,
                                          const Vector6d& leg_length_m, const Vector6d& q_guess,
                                          const ForwardKinematicsOptions& options = {});

/// True iff every leg length lies within [leg_min_length_m, leg_max_length_m].
bool LegLengthsWithinStroke(const PlatformParams& params, const Vector6d& leg_length_m);

/// Workspace check: every leg inside its stroke, tilt away from the Euler
/// singularity (|theta| < max_tilt_rad) and the platform above the base.
bool PoseInWorkspace(const PlatformParams& params, const Vector6d& q, double max_tilt_rad = 1.0);

}  // namespace stewart
