#include "stewart/identify/actuator_overlay.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace stewart::identify {
namespace {

std::string G(double v, int digits = 4) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

// "[a, b, c]" of one value over the legs.
std::string PerLeg(const ActuatorFit& fit, int value, int digits) {
  std::string text = "[";
  for (std::size_t i = 0; i < fit.legs.size(); ++i) {
    if (i > 0) text += ", ";
    text += G(fit.legs[i].values(value), digits);
  }
  return text + "]";
}

std::string Uncertainty(const ActuatorFit& fit, int v, const char* unit) {
  std::string text = "+- " + G(fit.sigma(v), 2) + unit;
  if (fit.sigma_prior(v) > 0.1 * fit.sigma_fit(v)) {
    text += " (fit " + G(fit.sigma_fit(v), 2) + ", assumed coulomb_friction_n " +
            G(fit.sigma_prior(v), 2) + ")";
  }
  if (fit.leg_spread(v) > 4.0) text += "; the legs differ: chi2/dof " + G(fit.leg_spread(v), 3);
  return text;
}

}  // namespace

std::string FormatActuatorOverlay(const ActuatorFit& fit, const ActuatorConfig& config,
                                  const ActuatorFitOptions& options,
                                  const std::string& provenance) {
  std::ostringstream out;
  std::istringstream lines(provenance);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  std::string legs, rms;
  for (std::size_t i = 0; i < fit.legs.size(); ++i) {
    legs += (i > 0 ? ", " : "") + std::to_string(fit.legs[i].leg);
    rms += (i > 0 ? ", " : "") + G(1e6 * fit.legs[i].residual_rms_m, 3);
  }
  out << "# fit: legs [" << legs << "], " << fit.samples << " samples of excursions, "
      << G(fit.duration_s, 3) << " s of procedure; residual rms per leg [" << rms << "] um\n";
  out << "# per leg: dead_band_duty " << PerLeg(fit, kDeadBandDuty, 4) << ", stall_force_n "
      << PerLeg(fit, kStallForceN, 4) << ", no_load_speed_mps " << PerLeg(fit, kNoLoadSpeedMps, 4)
      << ", reflected_mass_kg " << PerLeg(fit, kReflectedMassKg, 4) << "\n";
  out << "# measured as such: leg damping (back-EMF + screw) " << G(fit.values(kLegDampingNspm), 5)
      << " +- " << G(fit.sigma(kLegDampingNspm), 2) << " N s/m, force at full duty "
      << G(fit.values(kForceAtFullDutyN), 5) << " +- " << G(fit.sigma(kForceAtFullDutyN), 2)
      << " N, start duty (dead band and friction together) " << G(fit.values(kStartDuty), 4)
      << " +- " << G(fit.sigma(kStartDuty), 2) << "\n";
  std::string ramps;
  for (const LegFit& leg : fit.legs) {
    ramps += (ramps.empty() ? "" : ", ") + G(leg.ramp_start_duty[0], 3) + "/" +
             G(leg.ramp_start_duty[1], 3) + " (line " + G(leg.line_start_duty[0], 3) + "/" +
             G(leg.line_start_duty[1], 3) + ")";
  }
  out << "# duty at which each leg started to move on the ramps, extending/retracting: " << ramps
      << "\n";
  out << "# not identifiable, kept from the config: coulomb_friction_n " +
             G(options.coulomb_friction_n) + " N (assumed +- " +
             G(options.coulomb_friction_sigma_n) +
             " N: only dead band and friction together are seen; dead_band_duty and "
             "stall_force_n depend on it), back_drive_force_n " +
             G(config.motor.back_drive_force_n) + " N, lock_stiffness_npm " +
             G(config.motor.lock_stiffness_npm) + "; supply " + G(config.motor.supply_voltage_v) +
             " V, bridge drop " + G(config.motor.bridge_drop_v) + " V, rated " +
             G(config.motor.rated_voltage_v) + " V, screw friction " +
             G(config.viscous_friction_nspm) + " N s/m\n";
  out << "actuators:\n";
  const double f_full = fit.values(kForceAtFullDutyN);
  if (config.force_limit_n > f_full) {
    out << "  force_limit_n: " << G(std::floor(f_full), 6) << "  # the config's "
        << G(config.force_limit_n) << " N exceeds the identified force at full duty\n";
  }
  out << "  motor:\n";
  const double dead_band = fit.values(kDeadBandDuty);
  out << "    dead_band_duty: " << G(std::max(dead_band, 0.0), 5) << "  # "
      << Uncertainty(fit, kDeadBandDuty, "")
      << (dead_band < 0.0 ? "; fitted " + G(dead_band, 3) + " < 0: the assumed friction is too high"
                          : "")
      << "\n";
  out << "    stall_force_n: " << G(fit.values(kStallForceN), 5) << "  # "
      << Uncertainty(fit, kStallForceN, " N") << "\n";
  out << "    no_load_speed_mps: " << G(fit.values(kNoLoadSpeedMps), 5) << "  # "
      << Uncertainty(fit, kNoLoadSpeedMps, " m/s") << "\n";
  out << "    reflected_mass_kg: " << G(fit.values(kReflectedMassKg), 5) << "  # "
      << Uncertainty(fit, kReflectedMassKg, " kg") << "\n";
  return out.str();
}

}  // namespace stewart::identify
