#pragma once
/// @file taylor.h
/// Truncated Taylor series in time: exact derivatives of motion models.
///
/// A `Series<T, N>` holds the Taylor coefficients of a quantity x(t) about a
/// time t0, x(t0 + h) = Σ_{k=0..N} c[k] h^k, so c[k] = x^(k)(t0) / k!.
/// Arithmetic on series (sums, products, quotients, sin, cos, sqrt) follows
/// the standard recurrences of Taylor-mode automatic differentiation
/// (Griewank & Walther, "Evaluating Derivatives", ch. 13): every derivative
/// is computed in closed form from the formula of the motion, never by
/// differences, and is exact up to floating-point rounding.
///
/// T is `double` (scalars), `Vec3` (positions, axes) or `Mat3` (rotation
/// matrices). Products of different kinds (double·Vec3, Mat3·Mat3, Mat3·Vec3)
/// are Cauchy products of the coefficients.

#include <array>
#include <cmath>
#include <type_traits>
#include <utility>

#include "evio/core/eigen_types.h"

namespace evio::taylor {

namespace detail {

template <class T>
T zeroOf() {
  if constexpr (std::is_arithmetic_v<T>) {
    return T(0);
  } else {
    return T::Zero();
  }
}

inline double evalExpr(double x) { return x; }
template <class Derived>
auto evalExpr(const Eigen::MatrixBase<Derived>& x) {
  return x.eval();
}
template <class Lhs, class Rhs, int Option>
auto evalExpr(const Eigen::Product<Lhs, Rhs, Option>& x) {
  return x.eval();
}

template <class A, class B>
using ProductType = std::decay_t<decltype(evalExpr(std::declval<A>() * std::declval<B>()))>;

constexpr double factorial(int k) {
  double f = 1.0;
  for (int i = 2; i <= k; ++i) f *= static_cast<double>(i);
  return f;
}

}  // namespace detail

/// Truncated Taylor series of order N of a quantity of type T (see file comment).
template <class T, int N>
struct Series {
  static_assert(N >= 0, "order must be non-negative");
  std::array<T, N + 1> c;

  Series() { c.fill(detail::zeroOf<T>()); }

  /// A constant: c[0] = x, higher coefficients zero.
  static Series constant(const T& x) {
    Series s;
    s.c[0] = x;
    return s;
  }

  /// Value x(t0).
  const T& value() const { return c[0]; }

  /// k-th time derivative x^(k)(t0) = k! c[k].
  T derivative(int k) const { return c[static_cast<std::size_t>(k)] * detail::factorial(k); }
};

template <int N>
using Scalar = Series<double, N>;
template <int N>
using Vector3 = Series<Vec3, N>;
template <int N>
using Matrix3 = Series<Mat3, N>;

/// The time variable itself about t0: t(t0 + h) = t0 + h.
template <int N>
Scalar<N> variable(double t0) {
  Scalar<N> s;
  s.c[0] = t0;
  if constexpr (N >= 1) s.c[1] = 1.0;
  return s;
}

/// The series of the M-th derivative: coefficients c'[k] = c[k+M] (k+M)!/k!.
template <int M, class T, int N>
Series<T, N - M> differentiate(const Series<T, N>& x) {
  static_assert(M >= 0 && M <= N, "cannot differentiate beyond the order of the series");
  Series<T, N - M> d;
  for (int k = 0; k <= N - M; ++k) {
    double f = 1.0;
    for (int i = k + 1; i <= k + M; ++i) f *= static_cast<double>(i);
    d.c[static_cast<std::size_t>(k)] = x.c[static_cast<std::size_t>(k + M)] * f;
  }
  return d;
}

/// Lower order of the same series (drops the highest coefficients).
template <int M, class T, int N>
Series<T, M> truncate(const Series<T, N>& x) {
  static_assert(M <= N, "cannot raise the order of a series");
  Series<T, M> s;
  for (int k = 0; k <= M; ++k) s.c[static_cast<std::size_t>(k)] = x.c[static_cast<std::size_t>(k)];
  return s;
}

// Linear operations ---------------------------------------------------------

template <class T, int N>
Series<T, N> operator+(const Series<T, N>& a, const Series<T, N>& b) {
  Series<T, N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = a.c[k] + b.c[k];
  return s;
}

template <class T, int N>
Series<T, N> operator-(const Series<T, N>& a, const Series<T, N>& b) {
  Series<T, N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = a.c[k] - b.c[k];
  return s;
}

template <class T, int N>
Series<T, N> operator-(const Series<T, N>& a) {
  Series<T, N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = -a.c[k];
  return s;
}

/// Adds a constant to the value.
template <class T, int N>
Series<T, N> operator+(const Series<T, N>& a, const T& b) {
  Series<T, N> s = a;
  s.c[0] = s.c[0] + b;
  return s;
}
template <class T, int N>
Series<T, N> operator+(const T& b, const Series<T, N>& a) {
  return a + b;
}
template <class T, int N>
Series<T, N> operator-(const Series<T, N>& a, const T& b) {
  Series<T, N> s = a;
  s.c[0] = s.c[0] - b;
  return s;
}
template <class T, int N>
Series<T, N> operator-(const T& b, const Series<T, N>& a) {
  return (-a) + b;
}

/// Scaling by a constant number.
template <class T, int N>
Series<T, N> operator*(double f, const Series<T, N>& a) {
  Series<T, N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = f * a.c[k];
  return s;
}
template <class T, int N>
Series<T, N> operator*(const Series<T, N>& a, double f) {
  return f * a;
}

/// A scalar series times a constant vector or matrix: x(t) · V.
template <int N, class Derived>
Series<std::decay_t<decltype(std::declval<Derived>().eval())>, N> operator*(
    const Scalar<N>& a, const Eigen::MatrixBase<Derived>& v) {
  Series<std::decay_t<decltype(std::declval<Derived>().eval())>, N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = a.c[k] * v;
  return s;
}

/// Product of two series (Cauchy product of the coefficients; Leibniz rule).
template <class A, class B, int N>
Series<detail::ProductType<A, B>, N> operator*(const Series<A, N>& a, const Series<B, N>& b) {
  Series<detail::ProductType<A, B>, N> s;
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= k; ++j) s.c[k] = s.c[k] + detail::evalExpr(a.c[j] * b.c[k - j]);
  return s;
}

// Scalar functions -----------------------------------------------------------

/// Quotient a / b of scalar series; b(t0) must be non-zero.
/// q_k = (a_k − Σ_{j=1..k} b_j q_{k−j}) / b_0.
template <int N>
Scalar<N> operator/(const Scalar<N>& a, const Scalar<N>& b) {
  Scalar<N> q;
  for (int k = 0; k <= N; ++k) {
    double acc = a.c[k];
    for (int j = 1; j <= k; ++j) acc -= b.c[j] * q.c[k - j];
    q.c[k] = acc / b.c[0];
  }
  return q;
}

/// Sine and cosine of a scalar series at once:
/// k s_k = Σ_{j=1..k} j x_j c_{k−j},  k c_k = −Σ_{j=1..k} j x_j s_{k−j}.
template <int N>
void sinCos(const Scalar<N>& x, Scalar<N>* s, Scalar<N>* c) {
  s->c[0] = std::sin(x.c[0]);
  c->c[0] = std::cos(x.c[0]);
  for (int k = 1; k <= N; ++k) {
    double ss = 0.0, cc = 0.0;
    for (int j = 1; j <= k; ++j) {
      ss += j * x.c[j] * c->c[k - j];
      cc -= j * x.c[j] * s->c[k - j];
    }
    s->c[k] = ss / k;
    c->c[k] = cc / k;
  }
}

template <int N>
Scalar<N> sin(const Scalar<N>& x) {
  Scalar<N> s, c;
  sinCos(x, &s, &c);
  return s;
}

template <int N>
Scalar<N> cos(const Scalar<N>& x) {
  Scalar<N> s, c;
  sinCos(x, &s, &c);
  return c;
}

/// Exponential: k e_k = Σ_{j=1..k} j x_j e_{k−j}.
template <int N>
Scalar<N> exp(const Scalar<N>& x) {
  Scalar<N> e;
  e.c[0] = std::exp(x.c[0]);
  for (int k = 1; k <= N; ++k) {
    double acc = 0.0;
    for (int j = 1; j <= k; ++j) acc += j * x.c[j] * e.c[k - j];
    e.c[k] = acc / k;
  }
  return e;
}

/// Square root of a series with positive value:
/// r_k = (x_k − Σ_{j=1..k−1} r_j r_{k−j}) / (2 r_0).
template <int N>
Scalar<N> sqrt(const Scalar<N>& x) {
  Scalar<N> r;
  r.c[0] = std::sqrt(x.c[0]);
  for (int k = 1; k <= N; ++k) {
    double acc = x.c[k];
    for (int j = 1; j < k; ++j) acc -= r.c[j] * r.c[k - j];
    r.c[k] = acc / (2.0 * r.c[0]);
  }
  return r;
}

/// Integer power x^n, n >= 0, by repeated products.
template <int N>
Scalar<N> pow(const Scalar<N>& x, int n) {
  Scalar<N> r = Scalar<N>::constant(1.0);
  for (int i = 0; i < n; ++i) r = r * x;
  return r;
}

// Vector and matrix helpers ---------------------------------------------------

/// Builds a vector series from three scalar series.
template <int N>
Vector3<N> makeVector(const Scalar<N>& x, const Scalar<N>& y, const Scalar<N>& z) {
  Vector3<N> v;
  for (int k = 0; k <= N; ++k) v.c[k] = Vec3(x.c[k], y.c[k], z.c[k]);
  return v;
}

/// Component i of a vector series.
template <int N>
Scalar<N> component(const Vector3<N>& v, int i) {
  Scalar<N> s;
  for (int k = 0; k <= N; ++k) s.c[k] = v.c[k](i);
  return s;
}

template <int N>
Scalar<N> dot(const Vector3<N>& a, const Vector3<N>& b) {
  Scalar<N> s;
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= k; ++j) s.c[k] += a.c[j].dot(b.c[k - j]);
  return s;
}

template <int N>
Vector3<N> cross(const Vector3<N>& a, const Vector3<N>& b) {
  Vector3<N> s;
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= k; ++j) s.c[k] += a.c[j].cross(b.c[k - j]);
  return s;
}

/// v / |v| (v(t0) must be non-zero).
template <int N>
Vector3<N> normalized(const Vector3<N>& v) {
  const Scalar<N> inv = Scalar<N>::constant(1.0) / sqrt(dot(v, v));
  return inv * v;
}

template <int N>
Matrix3<N> transpose(const Matrix3<N>& m) {
  Matrix3<N> t;
  for (int k = 0; k <= N; ++k) t.c[k] = m.c[k].transpose();
  return t;
}

/// Matrix with the given column series.
template <int N>
Matrix3<N> fromColumns(const Vector3<N>& c0, const Vector3<N>& c1, const Vector3<N>& c2) {
  Matrix3<N> m;
  for (int k = 0; k <= N; ++k) {
    m.c[k].col(0) = c0.c[k];
    m.c[k].col(1) = c1.c[k];
    m.c[k].col(2) = c2.c[k];
  }
  return m;
}

}  // namespace evio::taylor
