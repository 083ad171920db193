#pragma once
// stewart_identify --mode actuators: the DC-motor legs' bring-up
// identification (docs/hardware.md, "Identify the actuators"). The
// procedure (identify/actuator_procedure.h) runs against
//   --plant sim                         plant_sim's Plant in process (no LCM)
//   --plant hw                          hw_bridge --bringup over LCM (started here)
//   --plant hw --device-emulator        ... with hw_emulator as the device
//   --plant hw --device-emulator --in-process
//                                       the emulator behind hw_bridge's library
//                                       in process (no LCM, no processes)
// then the fit (identify/actuator_fit.h) and the overlay.
#include <string>
#include <vector>

namespace stewart::identify {

struct ActuatorModeOptions {
  std::string plant = "sim";
  bool device_emulator = false;
  bool in_process = false;
  bool bridge_running = false;  ///< hw: a bridge in bring-up mode is already on the URL
  std::string out_path;
  std::string config_path;
  std::vector<std::string> overlay_paths;
  std::string truth_path;
  std::string seed;
  std::string lcm_url;
  std::string run_dir;
  int device_port = -1;  ///< hw: the device's UDP port (default hw_bridge.device_port)
  int local_port = -1;   ///< hw: the bridge's (default hw_bridge.local_port)
  std::vector<int> legs = {0, 1, 2, 3, 4, 5};
  int repeats = 1;
  double excursion_m = -1.0;      ///< default: the procedure's
  double max_duty = -1.0;         ///< default: hw_bridge.max_duty
  double guard_margin_m = -1.0;   ///< default: safety.leg_stroke.margin_m
  double speed_cap_mps = -1.0;    ///< default: twice the config motor's full-duty speed
  double coulomb_sigma_n = -1.0;  ///< default: the config's coulomb_friction_n (100 %)
  double sample_timeout_s = 2.0;
  double end_search_m = -1.0;      ///< pots: default the stroke-end run's
  double travel_speed_mps = -1.0;  ///< pots: default the stroke-end run's
};

/// Runs it; returns the process exit code (0, 1 on a guard trip or a
/// process failure). Throws InputError / IdentificationError for bad input.
int IdentifyActuators(const ActuatorModeOptions& options);

/// stewart_identify --mode pots: the pots' two-point calibration at the
/// stroke ends (identify/stroke_end_procedure.h), --plant hw only (the
/// calibration is hw_bridge's), as an overlay of hw_bridge.adc_retracted and
/// adc_extended. Same exit codes and throws.
int IdentifyPots(const ActuatorModeOptions& options);

}  // namespace stewart::identify
