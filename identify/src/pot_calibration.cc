#include "stewart/identify/pot_calibration.h"

#include <cmath>
#include <sstream>

#include "stewart/hw_bridge/calibration.h"
#include "stewart/identify/inertial_fit.h"

namespace stewart::identify {
namespace {

std::string PerLeg(const Vector6d& v, double scale, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << "[";
  for (int i = 0; i < kNumLegs; ++i) s << (i > 0 ? ", " : "") << scale * v(i);
  s << "]";
  return s.str();
}

}  // namespace

PotCalibration PotCalibrationFromEnds(const HwBridgeConfig& hw, double min_length_m,
                                      double stroke_m, const StrokeEndRecord& record) {
  const hw::LegCalibration in_use(hw, min_length_m, stroke_m);
  PotCalibration c;
  for (int i = 0; i < kNumLegs; ++i) {
    c.adc_retracted(i) = in_use.AdcCounts(i, record.retracted_reading_m(i));
    c.adc_extended(i) = in_use.AdcCounts(i, record.extended_reading_m(i));
    const double span = c.adc_extended(i) - c.adc_retracted(i);
    if (!(std::abs(span) >= 1.0) || !std::isfinite(span)) {
      throw IdentificationError("leg " + std::to_string(i) +
                                ": the pot reads the same at both stroke ends (span " +
                                std::to_string(span) + " counts): a broken pot or wiring");
    }
    c.count_m(i) = stroke_m / std::abs(span);
    const double retracted_m = min_length_m + hw.length_offset_m(i);
    c.retracted_error_m(i) = record.retracted_reading_m(i) - retracted_m;
    c.extended_error_m(i) = record.extended_reading_m(i) - (retracted_m + stroke_m);
  }
  return c;
}

std::string FormatPotOverlay(const PotCalibration& c, const StrokeEndRecord& record,
                             const std::string& provenance) {
  std::ostringstream out;
  std::istringstream lines(provenance);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  out << "# " << record.samples << " samples, " << record.duration_s << " s\n";
  out << "# readings at the stroke ends minus their lengths, with the calibration in use (mm):\n";
  out << "#   retracted " << PerLeg(c.retracted_error_m, 1e3, 3) << "\n";
  out << "#   extended  " << PerLeg(c.extended_error_m, 1e3, 3) << "\n";
  out << "# the readings' std while held at the ends (mm): retracted "
      << PerLeg(record.retracted_std_m, 1e3, 3) << ", extended "
      << PerLeg(record.extended_std_m, 1e3, 3) << "\n";
  out << "# one count (mm): " << PerLeg(c.count_m, 1e3, 4) << "\n";
  out << "hw_bridge:\n";
  out << "  adc_retracted: " << PerLeg(c.adc_retracted, 1.0, 2) << "\n";
  out << "  adc_extended: " << PerLeg(c.adc_extended, 1.0, 2) << "\n";
  return out.str();
}

}  // namespace stewart::identify
