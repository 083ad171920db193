#pragma once
// The external wrench of a truth's `disturbance` section as a function of
// time: the sum of a constant, steps, pulses, sinusoids and random pushes
// ([force (N); torque (N m)] in {B}, force through the origin of {P}).
#include <random>
#include <vector>

#include "stewart/plant_sim/truth.h"

namespace stewart {

class DisturbanceSource {
 public:
  /// `run_seed` is mixed into random_pushes.seed, so every run of a campaign
  /// draws its own pushes from one file.
  DisturbanceSource(const Disturbance& disturbance, unsigned run_seed);

  /// The wrench at t_s (s from the plant's start). Times must not decrease
  /// from call to call (a plant's clock); the random pushes are drawn in time
  /// order from their seed, so the sequence of values does not depend on how
  /// often it is asked. No allocation once running (ended pushes are dropped).
  Vector6d WrenchAt(double t_s);

  bool empty() const { return empty_; }

 private:
  void DrawPushesUntil(double t_s);

  Disturbance disturbance_;
  bool empty_;
  std::mt19937_64 rng_;
  double next_push_s_ = 0.0;
  double last_query_s_ = 0.0;
  std::vector<WrenchPulse> pushes_;  // drawn and not yet ended, in start order
};

}  // namespace stewart
