#include "stewart/identify/overlay_writer.h"

#include <cstdio>
#include <sstream>

namespace stewart::identify {
namespace {

// Seven significant digits: far below any value's uncertainty, and read
// back by YAML as the same double to that precision.
std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.7g", v);
  return text;
}

std::string List(const PlatformValues& v, int first) {
  return "[" + Number(v(first)) + ", " + Number(v(first + 1)) + ", " + Number(v(first + 2)) + "]";
}

std::string Sigma(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2g", v);
  return text;
}

std::string SigmaList(const PlatformValues& s, int first) {
  return "[" + Sigma(s(first)) + ", " + Sigma(s(first + 1)) + ", " + Sigma(s(first + 2)) + "]";
}

}  // namespace

std::string FormatPlatformOverlay(const PlatformEstimate& e, const InertialFit& fit,
                                  const std::string& provenance) {
  std::ostringstream o;
  std::istringstream lines(provenance);
  for (std::string line; std::getline(lines, line);) o << "# " << line << '\n';
  char text[256];
  std::snprintf(text, sizeof text,
                "# fit: %ld samples, %ld windows over %.1f s, condition number %.3g\n", fit.samples,
                fit.windows, fit.duration_s, fit.condition_number);
  o << text;
  std::snprintf(text, sizeof text,
                "# residual rms per window: x y z %.2g %.2g %.2g N s, phi theta psi %.2g %.2g "
                "%.2g N m s\n",
                fit.residual_rms(0), fit.residual_rms(1), fit.residual_rms(2), fit.residual_rms(3),
                fit.residual_rms(4), fit.residual_rms(5));
  o << text;
  std::snprintf(text, sizeof text,
                "#   (relative to the applied impulse: %.2g %.2g %.2g, %.2g %.2g %.2g)\n",
                fit.relative_residual(0), fit.relative_residual(1), fit.relative_residual(2),
                fit.relative_residual(3), fit.relative_residual(4), fit.relative_residual(5));
  o << text;
  o << "# Each value's one-sigma uncertainty in its comment (from the fit's residuals).\n";
  o << "platform:\n";
  o << "  mass_kg: " << Number(e.values(0)) << "  # +- " << Sigma(e.sigma(0)) << " kg\n";
  o << "  com_m: " << List(e.values, 1) << "  # in {P}; +- " << SigmaList(e.sigma, 1) << " m\n";
  o << "  inertia_kgm2: " << List(e.values, 4) << "  # about the CoM, {P} axes; +- "
    << SigmaList(e.sigma, 4) << " kg m^2\n";
  o << "  inertia_products_kgm2: " << List(e.values, 7) << "  # Ixy, Ixz, Iyz; +- "
    << SigmaList(e.sigma, 7) << " kg m^2\n";
  return o.str();
}

}  // namespace stewart::identify
