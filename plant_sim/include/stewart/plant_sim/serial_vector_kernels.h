#pragma once
// The vector kernels ARKODE and CVODE run on the simulator's state, compiled
// with this project's flags and installed in place of the ones of the
// SUNDIALS serial N_Vector.
//
// Why: Debian 12's SUNDIALS 6.4 (libsundials-dev 6.4.1) is built without
// optimisation: its serial kernels keep loop counters and pointers on the
// stack. One ERK step on the 18-value plant state makes many such calls (most
// from N_VLinearCombination falling back to a chain of N_VLinearSum), enough
// to dominate a plant tick (docs/performance.md, "plant_sim"). These are plain loops the compiler
// vectorises; the arithmetic per element is the textbook one (z = a x + b y,
// sums accumulated in index order), so results agree with the library's
// kernels to round-off (tests/plant_sim/serial_vector_kernels_test.cc).
#include <sundials/sundials_nvector.h>

namespace stewart {

/// Installs the kernels in the operation table of `v`, which must be a
/// serial N_Vector (N_VNew_Serial). Vectors cloned from `v` afterwards (an
/// integrator's whole workspace is cloned from the state vector it is
/// created with) inherit them. Also provides the fused operations
/// (linear combination, scale-add-multi, vector arrays), which SUNDIALS
/// leaves off by default: an ERK stage is then one call instead of one
/// N_VLinearSum per Butcher coefficient. Operations not listed in the .cc keep
/// the library's implementation.
void InstallSerialVectorKernels(N_Vector v);

}  // namespace stewart
