#pragma once
// Conversions between the LCM messages and the estimator library's types.
#include "stewart/estimator/ekf_types.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {

SensorSample SampleFromMessage(const sensor_t& msg);

/// state_t of an estimate: utime = sample_utime = the sensor sample's utime.
state_t StateFromEstimate(const Estimate& estimate, int64_t seq);

}  // namespace stewart
