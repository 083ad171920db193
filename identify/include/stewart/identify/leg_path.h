#pragma once
// One leg moving, the other five held by their self-locking screws: the
// platform has one degree of freedom, the moving leg's length L_i. Along it
// qd = s Ld_i with s = J_l^-1 e_i, and s^T H = (J_l s)^T = e_i^T, so the held
// legs' forces do no work and the model's dynamics (model/dynamics.h)
// projected onto s read
//
//   (m_r + m_p(q)) Ldd_i = F_i - F_load,i(q)      (+ terms in Ld^2, below)
//
// with F_i the leg's force along its axis (motor, back-EMF, friction),
//   m_p = s^T M_0 s     the platform body's and the legs' bodies' inertia
//                       seen along the leg (M_0: the model's M without the
//                       rotors; the moving rotor adds m_r, the held ones
//                       nothing),
//   F_load = s^T G      the leg's static load at q, the i-th entry of
//                       InverseDynamics(q, qd = 0, qdd = 0).
// The velocity terms s^T (C s + M s') Ld^2 are ~1e-4 N at the 17 mm/s of a
// P-16P's leg, against ~1 N of F_load: neglected.
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart::identify {

struct LegPathTerms {
  double load_n = 0.0;      ///< F_load (N), positive compresses the leg (it must push)
  double inertia_kg = 0.0;  ///< m_p (kg)
};

/// At pose q; `model` is the config's platform (its rotor mass is ignored).
/// NaN terms where J_l is singular.
LegPathTerms LegPathTermsAt(const PlatformParams& model, const Vector6d& q, int leg);

}  // namespace stewart::identify
