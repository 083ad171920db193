#include "stewart/plant_sim/truth.h"

namespace stewart {
namespace {

// Inertia tensor of a body about a point displaced by r from its CoM.
Matrix3d ParallelAxis(double mass_kg, const Vector3d& r) {
  return mass_kg * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
}

}  // namespace

PlatformParams WithPayload(const PlatformParams& platform, const Payload& payload) {
  if (!(payload.mass_kg > 0.0)) return platform;
  PlatformParams out = platform;
  const double m_p = platform.platform_mass_kg;
  const double m_l = payload.mass_kg;
  const double m = m_p + m_l;
  const Vector3d com = (m_p * platform.platform_com_in_P_m + m_l * payload.position_in_P_m) / m;
  const Vector3d& b = payload.box_m;
  const Vector3d box_diagonal =
      m_l / 12.0 *
      Vector3d(b(1) * b(1) + b(2) * b(2), b(0) * b(0) + b(2) * b(2), b(0) * b(0) + b(1) * b(1));
  const Matrix3d inertia =
      PlatformInertiaInP(platform) + ParallelAxis(m_p, platform.platform_com_in_P_m - com) +
      Matrix3d(box_diagonal.asDiagonal()) + ParallelAxis(m_l, payload.position_in_P_m - com);
  out.platform_mass_kg = m;
  out.platform_com_in_P_m = com;
  out.platform_inertia_kgm2 = inertia.diagonal();
  out.platform_inertia_products_kgm2 = Vector3d(inertia(0, 1), inertia(0, 2), inertia(1, 2));
  return out;
}

}  // namespace stewart
