#include "test_states.h"

#include "stewart/config/default_config.h"
#include "stewart/model/kinematics.h"

namespace stewart::test {

const StackConfig& DefaultConfig() { return DefaultStackConfig(); }

Vector6d RandomPose(std::mt19937* rng) {
  std::uniform_real_distribution<double> trans(-0.08, 0.08);
  std::uniform_real_distribution<double> height(0.38, 0.50);
  std::uniform_real_distribution<double> angle(-0.2, 0.2);
  for (;;) {
    Vector6d q;
    q << trans(*rng), trans(*rng), height(*rng), angle(*rng), angle(*rng), angle(*rng);
    if (PoseInWorkspace(DefaultConfig().platform, q)) return q;
  }
}

Vector6d RandomVelocity(std::mt19937* rng) {
  std::uniform_real_distribution<double> lin(-0.3, 0.3);
  std::uniform_real_distribution<double> ang(-1.0, 1.0);
  Vector6d qd;
  qd << lin(*rng), lin(*rng), lin(*rng), ang(*rng), ang(*rng), ang(*rng);
  return qd;
}

}  // namespace stewart::test
