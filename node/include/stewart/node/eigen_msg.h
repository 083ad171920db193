#pragma once
// Copies between LCM fixed arrays and Eigen vectors.
#include <Eigen/Core>
#include <cstddef>

namespace stewart {

template <std::size_t N>
Eigen::Matrix<double, static_cast<int>(N), 1> FromArray(const double (&a)[N]) {
  return Eigen::Map<const Eigen::Matrix<double, static_cast<int>(N), 1>>(a);
}

template <std::size_t N, typename Derived>
void ToArray(const Eigen::MatrixBase<Derived>& v, double (&a)[N]) {
  static_assert(Derived::SizeAtCompileTime == static_cast<int>(N), "size mismatch");
  // A named Map: `Map<...>(a) = v;` would parse as a declaration of `a`.
  Eigen::Map<Eigen::Matrix<double, static_cast<int>(N), 1>> out(a);
  out = v;
}

/// True iff every element is finite.
template <std::size_t N>
bool AllFinite(const double (&a)[N]) {
  return FromArray(a).allFinite();
}

}  // namespace stewart
