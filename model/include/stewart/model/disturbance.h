#pragma once
// The model error as one generalised force (docs/estimator.md, "Model error"):
//
//   M(q) qdd + C(q, qd) qd + G(q) = H(q) F + d
//
// d is in the coordinates of q: N on the translation rows ({B} axes), N m per
// rad of the Z-Y-X Euler angles on the rotation rows, like G. A payload, a
// mass or friction error, a constant or slowly varying external force all
// appear as d; the estimator estimates it, the controller cancels it and the
// safety filter keeps its limits for every d within `std_n` times its
// configured multiplier of the estimate.
#include "stewart/model/types.h"

namespace stewart {

struct GeneralizedDisturbance {
  Vector6d force_n = Vector6d::Zero();  ///< estimate of d
  Vector6d std_n = Vector6d::Zero();    ///< one-sigma uncertainty of each entry of d
};

}  // namespace stewart
