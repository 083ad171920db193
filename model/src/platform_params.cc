#include "stewart/model/platform_params.h"

#include <cmath>

namespace stewart {

Eigen::Matrix<double, 3, kNumLegs> JointsOnCircle(double radius_m,
                                                  const std::array<double, kNumLegs>& angles_deg) {
  Eigen::Matrix<double, 3, kNumLegs> joints;
  for (int i = 0; i < kNumLegs; ++i) {
    const double a = angles_deg[static_cast<size_t>(i)] * M_PI / 180.0;
    joints.col(i) << radius_m * std::cos(a), radius_m * std::sin(a), 0.0;
  }
  return joints;
}

}  // namespace stewart
