// Forward-mode dual numbers that nest: Dual<double> carries one first
// derivative, Dual<Dual<double>> the mixed second derivative of two
// directions (what linearize's orbit-frame chart needs: the chart's
// derivative along the flow, differentiated again along a state direction).
// Only what the orbit-frame chart uses is defined.
#pragma once

#include <cmath>

namespace kanegen {

template <class T>
struct Dual {
  T v{};  ///< value
  T d{};  ///< derivative along the dual direction
  Dual() = default;
  Dual(double x) : v(x), d(0.0) {}  // NOLINT: constants mix with duals
  Dual(const T& value, const T& derivative) : v(value), d(derivative) {}
};

/// The value of a (possibly nested) dual with every derivative dropped.
inline double value_of(double x) { return x; }
template <class T>
double value_of(const Dual<T>& x) { return value_of(x.v); }

template <class T> Dual<T> operator+(const Dual<T>& a, const Dual<T>& b) { return {a.v + b.v, a.d + b.d}; }
template <class T> Dual<T> operator-(const Dual<T>& a, const Dual<T>& b) { return {a.v - b.v, a.d - b.d}; }
template <class T> Dual<T> operator-(const Dual<T>& a) { return {-a.v, -a.d}; }
template <class T> Dual<T> operator*(const Dual<T>& a, const Dual<T>& b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
template <class T> Dual<T> operator/(const Dual<T>& a, const Dual<T>& b) {
  const T r = a.v / b.v;
  return {r, (a.d - r * b.d) / b.v};
}
template <class T> Dual<T> operator+(const Dual<T>& a, double b) { return {a.v + b, a.d}; }
template <class T> Dual<T> operator+(double a, const Dual<T>& b) { return {a + b.v, b.d}; }
template <class T> Dual<T> operator-(const Dual<T>& a, double b) { return {a.v - b, a.d}; }
template <class T> Dual<T> operator-(double a, const Dual<T>& b) { return {a - b.v, -b.d}; }
template <class T> Dual<T> operator*(const Dual<T>& a, double b) { return {a.v * b, a.d * b}; }
template <class T> Dual<T> operator*(double a, const Dual<T>& b) { return {a * b.v, a * b.d}; }
template <class T> Dual<T> operator/(const Dual<T>& a, double b) { return {a.v / b, a.d / b}; }
template <class T> Dual<T>& operator+=(Dual<T>& a, const Dual<T>& b) { return a = a + b; }
template <class T> Dual<T>& operator-=(Dual<T>& a, const Dual<T>& b) { return a = a - b; }

template <class T> Dual<T> sqrt(const Dual<T>& a) {
  using std::sqrt;
  const T r = sqrt(a.v);
  return {r, a.d / (2.0 * r)};
}
template <class T> Dual<T> sin(const Dual<T>& a) {
  using std::cos, std::sin;
  return {sin(a.v), cos(a.v) * a.d};
}
template <class T> Dual<T> cos(const Dual<T>& a) {
  using std::cos, std::sin;
  return {cos(a.v), -(sin(a.v) * a.d)};
}
template <class T> Dual<T> atan2(const Dual<T>& y, const Dual<T>& x) {
  using std::atan2;
  return {atan2(y.v, x.v), (x.v * y.d - y.v * x.d) / (x.v * x.v + y.v * y.v)};
}

}  // namespace kanegen
