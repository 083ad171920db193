#include "stewart/plant_sim/serial_vector_kernels.h"

#include <nvector/nvector_serial.h>

#include <cmath>
#include <stdexcept>

namespace stewart {
namespace {

// Element loops over one serial vector's data. Every kernel reads element i
// of all its inputs before it writes element i of its output, so an output
// may alias any input, as SUNDIALS allows for z = x or z = y.
realtype* Data(N_Vector v) { return NV_DATA_S(v); }
sunindextype Length(N_Vector v) { return NV_LENGTH_S(v); }

void LinearSum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = a * xd[i] + b * yd[i];
}

void Const(realtype c, N_Vector z) {
  realtype* zd = Data(z);
  const sunindextype n = Length(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}

void Prod(N_Vector x, N_Vector y, N_Vector z) {
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}

void Div(N_Vector x, N_Vector y, N_Vector z) {
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] / yd[i];
}

void Scale(realtype c, N_Vector x, N_Vector z) {
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}

void Abs(N_Vector x, N_Vector z) {
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = std::abs(xd[i]);
}

void Inv(N_Vector x, N_Vector z) {
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = 1.0 / xd[i];
}

void AddConst(N_Vector x, realtype b, N_Vector z) {
  const realtype* xd = Data(x);
  realtype* zd = Data(z);
  const sunindextype n = Length(x);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

realtype DotProd(N_Vector x, N_Vector y) {
  const realtype* xd = Data(x);
  const realtype* yd = Data(y);
  const sunindextype n = Length(x);
  realtype sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) sum += xd[i] * yd[i];
  return sum;
}

realtype MaxNorm(N_Vector x) {
  const realtype* xd = Data(x);
  const sunindextype n = Length(x);
  realtype max = 0.0;
  for (sunindextype i = 0; i < n; ++i) max = std::abs(xd[i]) > max ? std::abs(xd[i]) : max;
  return max;
}

realtype Min(N_Vector x) {
  const realtype* xd = Data(x);
  const sunindextype n = Length(x);
  realtype min = xd[0];
  for (sunindextype i = 1; i < n; ++i) min = xd[i] < min ? xd[i] : min;
  return min;
}

// sum (x_i w_i)^2: the local part of the weighted RMS norm (the error test
// of every step).
realtype WSqrSum(N_Vector x, N_Vector w) {
  const realtype* xd = Data(x);
  const realtype* wd = Data(w);
  const sunindextype n = Length(x);
  realtype sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const realtype p = xd[i] * wd[i];
    sum += p * p;
  }
  return sum;
}

realtype WrmsNorm(N_Vector x, N_Vector w) {
  return std::sqrt(WSqrSum(x, w) / static_cast<realtype>(Length(x)));
}

// z = sum_j c_j X_j. z may be X_0 (the only aliasing SUNDIALS allows):
// the first pass then scales it in place.
int LinearCombination(int nvec, realtype* c, N_Vector* X, N_Vector z) {
  if (nvec < 1) return -1;
  realtype* zd = Data(z);
  const sunindextype n = Length(z);
  const realtype* x0 = Data(X[0]);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c[0] * x0[i];
  for (int j = 1; j < nvec; ++j) {
    const realtype* xj = Data(X[j]);
    const realtype cj = c[j];
    for (sunindextype i = 0; i < n; ++i) zd[i] += cj * xj[i];
  }
  return 0;
}

// Z_j = a_j x + Y_j.
int ScaleAddMulti(int nvec, realtype* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  const realtype* xd = Data(x);
  const sunindextype n = Length(x);
  for (int j = 0; j < nvec; ++j) {
    const realtype* yd = Data(Y[j]);
    realtype* zd = Data(Z[j]);
    for (sunindextype i = 0; i < n; ++i) zd[i] = a[j] * xd[i] + yd[i];
  }
  return 0;
}

int DotProdMulti(int nvec, N_Vector x, N_Vector* Y, realtype* dots) {
  for (int j = 0; j < nvec; ++j) dots[j] = DotProd(x, Y[j]);
  return 0;
}

int LinearSumVectorArray(int nvec, realtype a, N_Vector* X, realtype b, N_Vector* Y, N_Vector* Z) {
  for (int j = 0; j < nvec; ++j) LinearSum(a, X[j], b, Y[j], Z[j]);
  return 0;
}

int ScaleVectorArray(int nvec, realtype* c, N_Vector* X, N_Vector* Z) {
  for (int j = 0; j < nvec; ++j) Scale(c[j], X[j], Z[j]);
  return 0;
}

int ConstVectorArray(int nvec, realtype c, N_Vector* Z) {
  for (int j = 0; j < nvec; ++j) Const(c, Z[j]);
  return 0;
}

int WrmsNormVectorArray(int nvec, N_Vector* X, N_Vector* W, realtype* norms) {
  for (int j = 0; j < nvec; ++j) norms[j] = WrmsNorm(X[j], W[j]);
  return 0;
}

}  // namespace

void InstallSerialVectorKernels(N_Vector v) {
  if (v == nullptr || N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL) {
    throw std::invalid_argument("InstallSerialVectorKernels: not a serial N_Vector");
  }
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = LinearSum;
  ops->nvconst = Const;
  ops->nvprod = Prod;
  ops->nvdiv = Div;
  ops->nvscale = Scale;
  ops->nvabs = Abs;
  ops->nvinv = Inv;
  ops->nvaddconst = AddConst;
  ops->nvdotprod = DotProd;
  ops->nvmaxnorm = MaxNorm;
  ops->nvwrmsnorm = WrmsNorm;
  ops->nvmin = Min;
  ops->nvdotprodlocal = DotProd;
  ops->nvmaxnormlocal = MaxNorm;
  ops->nvminlocal = Min;
  ops->nvwsqrsumlocal = WSqrSum;
  ops->nvlinearcombination = LinearCombination;
  ops->nvscaleaddmulti = ScaleAddMulti;
  ops->nvdotprodmulti = DotProdMulti;
  ops->nvlinearsumvectorarray = LinearSumVectorArray;
  ops->nvscalevectorarray = ScaleVectorArray;
  ops->nvconstvectorarray = ConstVectorArray;
  ops->nvwrmsnormvectorarray = WrmsNormVectorArray;
}

}  // namespace stewart
