#include "stewart/identify/ramp_start.h"

#include <cmath>

namespace stewart::identify {

RampStart RampStartDuty(const LegTestRecord& record, const ProcedureStep& ramp,
                        double reference_length_m, double rate_per_s) {
  const std::size_t n = ramp.end_sample - ramp.first_sample;
  if (n < 10) {
    throw IdentificationError("leg " + std::to_string(record.leg) + ": start ramp of " +
                              std::to_string(n) + " samples, too short to find the start duty");
  }
  const int64_t t0 = record.samples[ramp.first_sample].utime;
  const double t_end_s = static_cast<double>(record.samples[ramp.end_sample - 1].utime - t0) * 1e-6;
  double sum_xx = 0.0;
  for (std::size_t k = ramp.first_sample; k < ramp.end_sample; ++k) {
    const double x = ramp.sign * (record.samples[k].leg_length_m(record.leg) - reference_length_m);
    sum_xx += x * x;
  }
  RampStart best;
  double best_sse = INFINITY;
  for (double t_s = 0.0; t_s < t_end_s; t_s += 1e-3) {
    double sum_xw = 0.0, sum_ww = 0.0;
    for (std::size_t k = ramp.first_sample; k < ramp.end_sample; ++k) {
      const double t = static_cast<double>(record.samples[k].utime - t0) * 1e-6;
      if (t <= t_s) continue;
      const double w = (t - t_s) * (t - t_s);
      const double x =
          ramp.sign * (record.samples[k].leg_length_m(record.leg) - reference_length_m);
      sum_xw += x * w;
      sum_ww += w * w;
    }
    if (!(sum_ww > 0.0) || sum_xw <= 0.0) continue;
    const double sse = sum_xx - sum_xw * sum_xw / sum_ww;
    if (sse < best_sse) {
      best_sse = sse;
      best.start_s = t_s;
    }
  }
  best.duty = rate_per_s * best.start_s;
  best.rms_m = std::sqrt(std::max(0.0, best_sse) / static_cast<double>(n));
  return best;
}

}  // namespace stewart::identify
