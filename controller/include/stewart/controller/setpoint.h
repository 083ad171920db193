#pragma once
#include "stewart/model/types.h"

namespace stewart {

/// Desired motion at one instant, in the pose coordinates of q (m, rad; {P}
/// in {B}, Z-Y-X Euler angles) and their time derivatives.
struct Setpoint {
  Vector6d q_des = Vector6d::Zero();
  Vector6d qd_des = Vector6d::Zero();
  Vector6d qdd_des = Vector6d::Zero();  ///< feed-forward (the paper uses 0)

  /// A setpoint at rest at `pose`.
  static Setpoint HoldAt(const Vector6d& pose) {
    Setpoint s;
    s.q_des = pose;
    return s;
  }
  bool AllFinite() const { return q_des.allFinite() && qd_des.allFinite() && qdd_des.allFinite(); }
};

}  // namespace stewart
