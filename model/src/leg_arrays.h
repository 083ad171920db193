#pragma once
// The six legs side by side (structure of arrays), private to model/: row k
// of a LegVectors holds component k of one vector per leg, so an operation
// on all legs is one 6-wide array operation the compiler vectorises, rather
// than a 3-vector operation per leg, and the six square roots and divisions
// are independent instead of one dependency chain. Kinematics and dynamics
// both compute the leg geometry here, so InverseKinematics and
// EvaluateDynamics give bit-identical leg lengths at the same q (the plant's
// root functions reuse the latter for the former).
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart::internal {

using LegScalars = Eigen::Array<double, 1, kNumLegs>;
using LegVectors = Eigen::Array<double, 3, kNumLegs, Eigen::RowMajor>;

inline LegScalars Dot(const LegVectors& a, const LegVectors& b) { return (a * b).colwise().sum(); }

inline LegVectors Cross(const LegVectors& a, const LegVectors& b) {
  LegVectors c;
  c.row(0) = a.row(1) * b.row(2) - a.row(2) * b.row(1);
  c.row(1) = a.row(2) * b.row(0) - a.row(0) * b.row(2);
  c.row(2) = a.row(0) * b.row(1) - a.row(1) * b.row(0);
  return c;
}

/// a x b_i with the same a for every leg.
inline LegVectors Cross(const Vector3d& a, const LegVectors& b) {
  LegVectors c;
  c.row(0) = a.y() * b.row(2) - a.z() * b.row(1);
  c.row(1) = a.z() * b.row(0) - a.x() * b.row(2);
  c.row(2) = a.x() * b.row(1) - a.y() * b.row(0);
  return c;
}

/// sum_i a_i b_i^T (3x3).
inline Matrix3d SumOfOuterProducts(const LegVectors& a, const LegVectors& b) {
  return a.matrix() * b.matrix().transpose();
}

/// Paper eq. 1 for every leg, in {B}: p_i = R p_i^P (m), l_i = t + p_i - b_i,
/// L_i = |l_i| (m), n_i = l_i / L_i.
struct LegArrays {
  LegVectors offset;  ///< R p_i
  LegScalars length;  ///< L_i
  LegScalars inverse_length;
  LegVectors unit;  ///< n_i
};

inline LegArrays ComputeLegArrays(const PlatformParams& params, const Matrix3d& R,
                                  const Vector3d& t) {
  LegArrays legs;
  legs.offset = (R * params.platform_joints_in_P_m).array();
  const LegVectors leg = (legs.offset.colwise() + t.array()) - params.base_joints_in_B_m.array();
  legs.length = leg.square().colwise().sum().sqrt();
  legs.inverse_length = legs.length.inverse();
  legs.unit = leg.rowwise() * legs.inverse_length;
  return legs;
}

}  // namespace stewart::internal
