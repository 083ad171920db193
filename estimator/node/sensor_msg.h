#pragma once
// sensor_t into the estimator library's SensorSample (the node and replay).
#include "stewart/estimator/ekf_types.h"
#include "stewart/sensor_t.hpp"

namespace stewart {

SensorSample SampleFromMessage(const sensor_t& msg);

}  // namespace stewart
