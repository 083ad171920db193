#include "stewart/plant_sim/disturbance_source.h"

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "stewart/common/check.h"

namespace stewart {
namespace {

constexpr double kTwoPi = 6.283185307179586;

bool Active(double t_s, double start_s, double duration_s) {
  return t_s >= start_s && t_s < start_s + duration_s;
}

}  // namespace

DisturbanceSource::DisturbanceSource(const Disturbance& disturbance, unsigned run_seed)
    : disturbance_(disturbance),
      empty_(disturbance.constant.isZero() && disturbance.steps.empty() &&
             disturbance.pulses.empty() && disturbance.sinusoids.empty() &&
             !(disturbance.random_pushes.rate_hz > 0.0 &&
               disturbance.random_pushes.max_force_n > 0.0)),
      rng_((static_cast<std::uint64_t>(disturbance.random_pushes.seed) << 32) ^ run_seed) {
  // Overlapping pushes at once: rate x duration on average; room for far more.
  pushes_.reserve(64);
  if (disturbance_.random_pushes.rate_hz > 0.0) {
    next_push_s_ = std::exponential_distribution<double>(disturbance_.random_pushes.rate_hz)(rng_);
  }
}

void DisturbanceSource::DrawPushesUntil(double t_s) {
  const RandomPushes& p = disturbance_.random_pushes;
  if (!(p.rate_hz > 0.0) || !(p.max_force_n > 0.0)) return;
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::exponential_distribution<double> gap(p.rate_hz);
  while (next_push_s_ <= t_s) {
    Vector3d direction(normal(rng_), normal(rng_), normal(rng_));
    const double norm = direction.norm();
    direction = norm > 0.0 ? Vector3d(direction / norm) : Vector3d::UnitX();
    WrenchPulse push;
    push.start_s = next_push_s_;
    push.duration_s = p.duration_s;
    push.wrench.head<3>() = unit(rng_) * p.max_force_n * direction;
    pushes_.push_back(push);
    next_push_s_ += gap(rng_);
  }
}

Vector6d DisturbanceSource::WrenchAt(double t_s) {
  if (empty_) return Vector6d::Zero();
  STEWART_CHECK(t_s >= last_query_s_, "DisturbanceSource::WrenchAt: time went backwards");
  last_query_s_ = t_s;
  Vector6d w = disturbance_.constant;
  for (const WrenchStep& s : disturbance_.steps)
    if (t_s >= s.start_s) w += s.wrench;
  for (const WrenchPulse& p : disturbance_.pulses)
    if (Active(t_s, p.start_s, p.duration_s)) w += p.wrench;
  for (const WrenchSinusoid& s : disturbance_.sinusoids)
    w += s.amplitude * std::sin(kTwoPi * s.frequency_hz * t_s + s.phase_rad);
  DrawPushesUntil(t_s);
  // Every push lasts duration_s and they start in order: the ended ones are
  // a prefix.
  std::size_t ended = 0;
  while (ended < pushes_.size() && t_s >= pushes_[ended].start_s + pushes_[ended].duration_s) {
    ++ended;
  }
  pushes_.erase(pushes_.begin(), pushes_.begin() + static_cast<std::ptrdiff_t>(ended));
  for (const WrenchPulse& p : pushes_)
    if (Active(t_s, p.start_s, p.duration_s)) w += p.wrench;
  return w;
}

}  // namespace stewart
