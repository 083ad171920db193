#include "actuator_mode.h"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>

#include "child_process.h"
#include "lcm_actuator_device.h"
#include "stewart/config/config_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/hw_bridge/bringup.h"
#include "stewart/identify/actuator_fit.h"
#include "stewart/identify/actuator_overlay.h"
#include "stewart/identify/actuator_procedure.h"
#include "stewart/identify/emulator_device.h"
#include "stewart/identify/plant_device.h"
#include "stewart/identify/pot_calibration.h"
#include "stewart/identify/stroke_end_procedure.h"
#include "stewart/model/kinematics.h"
#include "stewart/node/exit_code.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/stop_signal.h"

namespace fs = std::filesystem;

namespace stewart::identify {
namespace {

std::string Now(const char* format) {
  const std::time_t t = std::time(nullptr);
  char text[64];
  std::strftime(text, sizeof text, format, std::localtime(&t));
  return text;
}

std::string PrivateUrl() {
  std::random_device random;
  return "udpm://239.255.76.67:" + std::to_string(20000 + random() % 20000) + "?ttl=0";
}

PlantTruth TruthFor(const StackConfig& config, const ActuatorModeOptions& o) {
  PlantTruth truth = LoadPlantTruth(config, o.truth_path);
  if (!o.seed.empty()) {
    try {
      truth.sensors.seed = static_cast<unsigned>(std::stoul(o.seed));
    } catch (const std::exception&) {
      throw InputError("--seed", "must be a non-negative integer, got '" + o.seed + "'");
    }
  }
  return truth;
}

ActuatorProcedureOptions ProcedureOptionsFor(const StackConfig& c, const ActuatorModeOptions& o) {
  ActuatorProcedureOptions p;
  p.legs = o.legs;
  p.repeats = o.repeats;
  if (o.excursion_m > 0.0) p.excursion_m = o.excursion_m;
  p.max_duty = o.max_duty > 0.0 ? o.max_duty : c.hw_bridge.max_duty;
  for (DutyLevels& l : p.levels) {
    l.hi = std::min(l.hi, p.max_duty);
    l.lo = std::min(l.lo, 0.5 * l.hi);
  }
  p.check_duty = std::min(p.check_duty, p.max_duty);
  p.ramp_max_duty = std::min(p.ramp_max_duty, p.max_duty);
  p.guard = hw::DefaultBringupGuard(
      c.platform.leg_min_length_m, c.platform.leg_max_length_m,
      o.guard_margin_m > 0.0 ? o.guard_margin_m : c.safety.leg_stroke.margin_m, c.actuators.motor);
  if (o.speed_cap_mps > 0.0) p.guard.speed_cap_mps = o.speed_cap_mps;
  ValidateProcedureOptions(p);
  return p;
}

std::vector<std::string> ConfigArgs(const ActuatorModeOptions& o, const std::string& url) {
  std::vector<std::string> args = {"--config", o.config_path.empty()
                                                   ? DefaultConfigPath()
                                                   : fs::absolute(o.config_path).string()};
  for (const std::string& overlay : o.overlay_paths) {
    args.push_back("--overlay");
    args.push_back(fs::absolute(overlay).string());
  }
  args.push_back("--lcm-url");
  args.push_back(url);
  return args;
}

// The procedure against hw_bridge --bringup over LCM, starting it (and the
// emulator) unless told a bridge runs.
using DeviceRun = std::function<void(ActuatorDevice*)>;

// `guard_args`: hw_bridge's bring-up guard flags, the run's own guard.
void RunOverLcm(const StackConfig& config, const ActuatorModeOptions& o,
                const std::vector<std::string>& guard_args, const std::string& run_dir,
                const DeviceRun& run) {
  const std::string url = config.lcm.url;
  const int device_port = o.device_port >= 0 ? o.device_port : config.hw_bridge.device_port;
  const int local_port = o.local_port >= 0 ? o.local_port : config.hw_bridge.local_port;
  std::vector<std::unique_ptr<ChildProcess>> children;
  if (o.device_emulator) {
    std::vector<std::string> args = {HW_EMULATOR_EXE};
    for (const std::string& a : ConfigArgs(o, url)) args.push_back(a);
    for (const std::string& a : {std::string("--device-port"), std::to_string(device_port),
                                 std::string("--host-port"), std::to_string(local_port)}) {
      args.push_back(a);
    }
    if (!o.truth_path.empty()) {
      args.push_back("--truth");
      args.push_back(fs::absolute(o.truth_path).string());
    }
    children.push_back(
        std::make_unique<ChildProcess>("hw_emulator", args, run_dir + "/hw_emulator.log"));
  }
  if (!o.bridge_running) {
    std::vector<std::string> args = {HW_BRIDGE_EXE, "--bringup"};
    for (const std::string& a : ConfigArgs(o, url)) args.push_back(a);
    for (const std::string& a : {std::string("--device-port"), std::to_string(device_port),
                                 std::string("--local-port"), std::to_string(local_port)}) {
      args.push_back(a);
    }
    for (const std::string& a : guard_args) args.push_back(a);
    children.push_back(
        std::make_unique<ChildProcess>("hw_bridge", args, run_dir + "/hw_bridge.log"));
  }
  spdlog::info("hw: LCM {}, device UDP {} / bridge {}, process logs in {}", url, device_port,
               local_port, run_dir);
  // A stop signal ends the procedure at the next sample (zero duty), and the
  // processes are stopped below, not left running.
  InstallStopSignalHandlers();
  const std::unique_ptr<lcm::LCM> lcm = MakeLcm(url);
  LcmActuatorDevice device(config, lcm.get(), o.sample_timeout_s);
  const auto stop_all = [&]() {
    for (auto it = children.rbegin(); it != children.rend(); ++it) (*it)->Stop();
  };
  try {
    run(&device);
    stop_all();
    spdlog::info("hw: {} sensor samples, {} echoes, {} skipped (the tool fell behind)",
                 device.sensor_messages(), device.echo_messages(), device.skipped_samples());
  } catch (...) {
    for (const auto& child : children) {
      if (!child->Running()) {
        spdlog::error("{} exited with {}; its log ends:\n{}", child->name(), child->exit_code(),
                      child->LogTail(8));
      }
    }
    stop_all();
    throw;
  }
}

// The config, with the checks both bring-up modes share.
StackConfig BringupConfig(const ActuatorModeOptions& o) {
  StackConfig config = o.config_path.empty() ? LoadStackConfig(DefaultConfigPath(), o.overlay_paths)
                                             : LoadStackConfig(o.config_path, o.overlay_paths);
  if (config.actuators.kind != ActuatorKind::kDcMotor) {
    throw InputError("actuators.model",
                     "the stack's legs are not DC motors: identify them with --overlay "
                     "config/overlays/p16p.yaml");
  }
  if (o.plant == "sim" && (o.device_emulator || o.in_process)) {
    throw InputError("--device-emulator", "goes with --plant hw");
  }
  if (o.in_process && !o.device_emulator) {
    throw InputError("--in-process", "needs --device-emulator (a real device is not in process)");
  }
  if (!o.truth_path.empty() && o.plant == "hw" && !o.device_emulator) {
    throw InputError("--truth",
                     "describes a simulated plant: use --plant sim or --device-emulator");
  }
  return config;
}

std::string RunDir(const ActuatorModeOptions& o, const char* what) {
  return o.run_dir.empty()
             ? std::string(STEWART_SOURCE_DIR) + "/runs/" + Now("%Y%m%d-%H%M%S") + "-" + what
             : fs::absolute(o.run_dir).string();
}

bool WriteOverlay(const std::string& path, const std::string& overlay) {
  std::ofstream out(path);
  out << overlay;
  if (!out) spdlog::error("cannot write '{}'", path);
  return static_cast<bool>(out);
}

}  // namespace

int IdentifyActuators(const ActuatorModeOptions& o) {
  StackConfig config = BringupConfig(o);
  const ActuatorProcedureOptions procedure = ProcedureOptionsFor(config, o);
  const ProgressFn progress = [](const std::string& line) { spdlog::info("{}", line); };
  const std::string run_dir = RunDir(o, "identify-actuators");

  std::string provenance = "stewart_identify --mode actuators --plant " + o.plant;
  ActuatorRecord record;
  try {
    if (o.plant == "sim") {
      PlantDevice device(config, TruthFor(config, o));
      record = RunActuatorProcedure(&device, procedure, progress);
      provenance += " (in process)";
    } else if (o.in_process) {
      hw::BringupOptions bringup;
      bringup.enabled = true;
      bringup.guard = procedure.guard;
      EmulatorDevice device(config, TruthFor(config, o), bringup);
      record = RunActuatorProcedure(&device, procedure, progress);
      provenance += " --device-emulator (in process)";
    } else {
      config.lcm.url = o.lcm_url.empty() ? PrivateUrl() : o.lcm_url;
      fs::create_directories(run_dir);
      const hw::LegGuardLimits& g = procedure.guard;
      RunOverLcm(config, o,
                 {"--bringup-margin", std::to_string(g.margin_m), "--bringup-speed-cap",
                  std::to_string(g.speed_cap_mps)},
                 run_dir, [&](ActuatorDevice* device) {
                   record = RunActuatorProcedure(device, procedure, progress);
                 });
      provenance += std::string(o.device_emulator ? " --device-emulator" : "") +
                    " via hw_bridge --bringup, logs " + run_dir;
    }
  } catch (const GuardTrip& trip) {
    spdlog::error("{}", trip.what());
    spdlog::error("the procedure stopped; nothing was written");
    return ToInt(ExitCode::kFault);
  }
  if (!o.truth_path.empty()) provenance += ", truth " + o.truth_path;
  if (!o.seed.empty()) provenance += ", seed " + o.seed;

  ActuatorFitOptions fit_options;
  fit_options.coulomb_friction_n = config.actuators.motor.coulomb_friction_n;
  fit_options.coulomb_friction_sigma_n =
      o.coulomb_sigma_n >= 0.0 ? o.coulomb_sigma_n : config.actuators.motor.coulomb_friction_n;
  const ActuatorFit fit = FitActuators(config.platform, config.actuators, record, fit_options);
  provenance += "\nidentified " + Now("%Y-%m-%d %H:%M") +
                "\napply with: tools/launch.sh --plant hw --overlay config/overlays/p16p.yaml " +
                "--overlay " + o.out_path;
  const std::string overlay = FormatActuatorOverlay(fit, config.actuators, fit_options, provenance);
  if (!WriteOverlay(o.out_path, overlay)) return ToInt(ExitCode::kFault);
  spdlog::info(
      "stall force {:.1f} +- {:.2g} N, no-load speed {:.5f} +- {:.2g} m/s, rotor mass {:.1f} +- "
      "{:.2g} kg, dead band {:.4f} +- {:.2g}; written to {}",
      fit.values(kStallForceN), fit.sigma(kStallForceN), fit.values(kNoLoadSpeedMps),
      fit.sigma(kNoLoadSpeedMps), fit.values(kReflectedMassKg), fit.sigma(kReflectedMassKg),
      fit.values(kDeadBandDuty), fit.sigma(kDeadBandDuty), o.out_path);
  std::fputs(overlay.c_str(), stdout);
  return ToInt(ExitCode::kOk);
}

int IdentifyPots(const ActuatorModeOptions& o) {
  StackConfig config = BringupConfig(o);
  if (o.plant != "hw") {
    throw InputError("--plant",
                     "the pots' calibration is hw_bridge's (plant_sim reads lengths, not counts): "
                     "use --plant hw (with --device-emulator for a rehearsal)");
  }
  StrokeEndOptions ends;
  ends.min_length_m = config.platform.leg_min_length_m;
  ends.max_length_m = config.platform.leg_max_length_m;
  if (o.end_search_m > 0.0) ends.search_m = o.end_search_m;
  if (o.travel_speed_mps > 0.0) ends.travel_speed_mps = o.travel_speed_mps;
  ends.max_duty = o.max_duty > 0.0 ? o.max_duty : config.hw_bridge.max_duty;
  ends.push_duty = std::min(ends.push_duty, ends.max_duty);
  ends.motor = config.actuators.motor;
  ends.speed_cap_mps = o.speed_cap_mps > 0.0
                           ? o.speed_cap_mps
                           : hw::DefaultBringupGuard(ends.min_length_m, ends.max_length_m, 0.001,
                                                     config.actuators.motor)
                                 .speed_cap_mps;
  ValidateStrokeEndOptions(ends);
  const ProgressFn progress = [](const std::string& line) { spdlog::info("{}", line); };
  const double stroke_m = ends.max_length_m - ends.min_length_m;
  const double home_leg_m = InverseKinematics(config.platform, config.home_pose).mean();
  spdlog::warn(
      "pots: all six legs go to their retracted ends, then to their extended ends (the platform "
      "sinks {:.0f} mm and rises {:.0f} mm from home, about level): keep its travel clear",
      1e3 * (home_leg_m - ends.min_length_m), 1e3 * (ends.max_length_m - home_leg_m));

  // The bridge decodes readings beyond the nominal ends only with a fault
  // margin that reaches past them.
  StackConfig bridge_config = config;
  bridge_config.hw_bridge.adc_fault_margin_counts =
      hw::FaultMarginForSearch(config.hw_bridge, stroke_m, ends.search_m);
  std::string provenance = "stewart_identify --mode pots --plant hw";
  StrokeEndRecord record;
  try {
    if (o.in_process) {
      hw::BringupOptions bringup;
      bringup.enabled = true;
      bringup.guard = StrokeEndGuard(ends);
      EmulatorDevice device(bridge_config, TruthFor(config, o), bringup);
      record = RunStrokeEndProcedure(&device, ends, progress);
      provenance += " --device-emulator (in process)";
    } else {
      config.lcm.url = o.lcm_url.empty() ? PrivateUrl() : o.lcm_url;
      const std::string run_dir = RunDir(o, "identify-pots");
      fs::create_directories(run_dir);
      RunOverLcm(config, o,
                 {"--bringup-end-search", std::to_string(ends.search_m), "--bringup-speed-cap",
                  std::to_string(ends.speed_cap_mps)},
                 run_dir, [&](ActuatorDevice* device) {
                   record = RunStrokeEndProcedure(device, ends, progress);
                 });
      provenance += std::string(o.device_emulator ? " --device-emulator" : "") +
                    " via hw_bridge --bringup --bringup-end-search, logs " + run_dir;
    }
  } catch (const GuardTrip& trip) {
    spdlog::error("{}", trip.what());
    spdlog::error("the run stopped; nothing was written");
    return ToInt(ExitCode::kFault);
  }
  if (!o.truth_path.empty()) provenance += ", truth " + o.truth_path;
  if (!o.seed.empty()) provenance += ", seed " + o.seed;
  provenance += "\nidentified " + Now("%Y-%m-%d %H:%M") +
                "\napply with: tools/launch.sh --plant hw --overlay config/overlays/p16p.yaml " +
                "--overlay " + o.out_path;
  const PotCalibration calibration =
      PotCalibrationFromEnds(config.hw_bridge, ends.min_length_m, stroke_m, record);
  const std::string overlay = FormatPotOverlay(calibration, record, provenance);
  if (!WriteOverlay(o.out_path, overlay)) return ToInt(ExitCode::kFault);
  spdlog::info("largest reading error at the ends, now calibrated out: {:.2f} mm; written to {}",
               1e3 * std::max(calibration.retracted_error_m.cwiseAbs().maxCoeff(),
                              calibration.extended_error_m.cwiseAbs().maxCoeff()),
               o.out_path);
  std::fputs(overlay.c_str(), stdout);
  return ToInt(ExitCode::kOk);
}

}  // namespace stewart::identify
