#pragma once
// The two-point pot calibration from the stroke-end run
// (stroke_end_procedure.h; docs/hardware.md, "Calibrate the pots at the
// stroke ends"). hw_bridge decodes a leg's ADC counts c linearly
// (hw_bridge/calibration.h):
//   L = min_length_m + length_offset_m[i] + (c - adc_retracted[i]) /
//       (adc_extended[i] - adc_retracted[i]) stroke_m,
// so the mean reading at a stroke end under the calibration in use is the
// mean count there, mapped back exactly (LegCalibration::AdcCounts). Those
// counts become the new adc_retracted[i] and adc_extended[i]: the ends then
// decode to their known lengths. length_offset_m (the joint-to-joint length
// at full retraction, callipers) is kept.
#include <string>

#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/identify/stroke_end_procedure.h"

namespace stewart::identify {

struct PotCalibration {
  Vector6d adc_retracted = Vector6d::Zero();  ///< counts (unrounded)
  Vector6d adc_extended = Vector6d::Zero();
  /// Readings at the ends minus their known lengths, under the calibration
  /// in use (m): what the new one removes.
  Vector6d retracted_error_m = Vector6d::Zero();
  Vector6d extended_error_m = Vector6d::Zero();
  /// One count's length at the new span (m), per leg.
  Vector6d count_m = Vector6d::Zero();
};

/// `hw` is the calibration the run's readings were decoded with; min_length_m
/// and stroke_m the config's stroke (platform.leg_min_length_m, its
/// stroke). Throws IdentificationError for a degenerate span.
PotCalibration PotCalibrationFromEnds(const HwBridgeConfig& hw, double min_length_m,
                                      double stroke_m, const StrokeEndRecord& record);

/// The config overlay (hw_bridge.adc_retracted, adc_extended), with the
/// provenance and the measured errors as comments.
std::string FormatPotOverlay(const PotCalibration& calibration, const StrokeEndRecord& record,
                             const std::string& provenance);

}  // namespace stewart::identify
