#pragma once
// Fixed-size Eigen types shared by every component. Fixed sizes keep the hot
// paths free of heap allocation.
//
// Names and frames, one convention for the whole tree (docs/model.md, "Names
// and frames"): a name ends in its unit (`_m`, `_rad`, `_n`, `_mps`,
// `_kgm2`; none for a dimensionless value), and a vector whose frame matters
// names the frame it is expressed in before the unit: `_in_B` for the base
// frame {B} (z up, origin at the centre of the base joint circle), `_in_P`
// for the platform frame {P} (origin at the centre of the platform joint
// circle). `base_joints_in_B_m` are lengths in {B}; `unit_in_B` are unit
// vectors in {B}. q = [x y z phi theta psi] is the pose of {P} in {B}.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string_view>

namespace stewart {

constexpr int kNumLegs = 6;
constexpr int kNumAxes = 6;

using Vector3d = Eigen::Vector3d;
using Matrix3d = Eigen::Matrix3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

/// Pose axes in the order of q = [x y z phi theta psi] (m, m, m, rad, rad, rad).
enum class Axis : int { kX = 0, kY = 1, kZ = 2, kPhi = 3, kTheta = 4, kPsi = 5 };

/// Names of the pose axes as used in the config and the docs.
inline constexpr std::array<std::string_view, kNumAxes> kAxisNames = {"x",   "y",     "z",
                                                                      "phi", "theta", "psi"};

}  // namespace stewart
