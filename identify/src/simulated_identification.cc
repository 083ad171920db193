#include "stewart/identify/simulated_identification.h"

#include "stewart/hw_bridge/bringup.h"
#include "stewart/identify/actuator_fit.h"
#include "stewart/identify/actuator_overlay.h"
#include "stewart/identify/actuator_procedure.h"
#include "stewart/identify/plant_device.h"

namespace stewart::identify {

std::string IdentifyActuatorsInSimulation(const StackConfig& config, const PlantTruth& truth,
                                          const std::string& provenance) {
  PlantDevice device(config, truth);
  ActuatorProcedureOptions procedure;
  procedure.guard =
      hw::DefaultBringupGuard(config.platform.leg_min_length_m, config.platform.leg_max_length_m,
                              config.safety.leg_stroke.margin_m, config.actuators.motor);
  ValidateProcedureOptions(procedure);
  // The friction is not identifiable (docs/hardware.md): the config's, +-100 %.
  ActuatorFitOptions fit_options;
  fit_options.coulomb_friction_n = config.actuators.motor.coulomb_friction_n;
  fit_options.coulomb_friction_sigma_n = fit_options.coulomb_friction_n;
  const ActuatorFit fit = FitActuators(config.platform, config.actuators,
                                       RunActuatorProcedure(&device, procedure), fit_options);
  return FormatActuatorOverlay(fit, config.actuators, fit_options, provenance);
}

}  // namespace stewart::identify
