#pragma once
// The identified values as a config overlay (tools/launch.sh --overlay FILE):
// only the keys identified, each with its one-sigma uncertainty and the fit's
// residual in comments.
#include <string>

#include "stewart/identify/inertial_fit.h"
#include "stewart/identify/platform_estimate.h"

namespace stewart::identify {

/// YAML text: `platform: {mass_kg, com_m, inertia_kgm2, inertia_products_kgm2}`
/// with comments. `provenance` (one or more lines, without '#') is written
/// first, as comments: what was run, on which log.
std::string FormatPlatformOverlay(const PlatformEstimate& estimate, const InertialFit& fit,
                                  const std::string& provenance);

}  // namespace stewart::identify
