#pragma once
// The duty at which a leg starts to move, from a start ramp of the
// procedure (actuator_procedure.h): the duty rises linearly, r t, and above
// the start duty d_s the leg's speed grows with the duty (the fit's speed /
// duty line), so its travel from rest is
//   x(t) = c max(0, t - t_s)^2,   d_s = r t_s.
// t_s and c by least squares over the ramp's samples (t_s on a 1 ms grid, c
// in closed form). The rotor's lag (~10 ms at r = 0.1/s: 0.001 of duty) is
// below the grid's resolution in duty.
#include "stewart/identify/actuator_procedure.h"

namespace stewart::identify {

struct RampStart {
  double duty = 0.0;     ///< |duty| at which the leg starts to move
  double start_s = 0.0;  ///< t_s, from the ramp's first sample
  double rms_m = 0.0;    ///< residual of the fit
};

/// `ramp` is a kRamp step of `record`; reference_length_m the leg's length
/// at rest before it. Throws IdentificationError when the step holds fewer
/// than 10 samples.
RampStart RampStartDuty(const LegTestRecord& record, const ProcedureStep& ramp,
                        double reference_length_m, double rate_per_s);

}  // namespace stewart::identify
