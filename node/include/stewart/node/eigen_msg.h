#pragma once
// Copies between LCM fixed arrays and Eigen vectors, and field by field
// between an LCM message and its library struct.
#include <Eigen/Core>
#include <cstddef>
#include <tuple>
#include <utility>

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

/// One field: a message array into a library vector, a library vector into
/// a message array, anything else assigned.
template <typename From, typename To>
void CopyField(const From& from, To& to) {
  to = from;
}
template <int N>
void CopyField(const double (&from)[N], Eigen::Matrix<double, N, 1>& to) {
  to = FromArray(from);
}
template <int N>
void CopyField(const Eigen::Matrix<double, N, 1>& from, double (&to)[N]) {
  ToArray(from, to);
}

/// Copies every field of `from` into the field of `to` at the same place:
/// both are std::tie of corresponding fields, so one list of field names
/// serves both directions.
template <typename From, typename To>
void CopyFields(const From& from, const To& to) {
  static_assert(std::tuple_size_v<From> == std::tuple_size_v<To>, "field lists differ");
  std::apply(
      [&to](const auto&... source) {
        std::apply([&source...](auto&... target) { (CopyField(source, target), ...); }, to);
      },
      from);
}

}  // namespace stewart
