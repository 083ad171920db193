#include "stewart/model/sensor_params.h"

#include <cmath>

namespace stewart {

double LegAdcStepM(const SensorConfig& sensors, double stroke_m) {
  if (sensors.leg_adc_bits <= 0) return 0.0;
  return stroke_m / (std::ldexp(1.0, sensors.leg_adc_bits) - 1.0);
}

}  // namespace stewart
