#include "polynomial_roots.h"

#include <algorithm>
#include <cmath>

namespace evio::detail {

namespace {

std::vector<double> derivative(const std::vector<double>& c) {
  std::vector<double> d;
  for (std::size_t i = 1; i < c.size(); ++i) d.push_back(static_cast<double>(i) * c[i]);
  return d;
}

// Bisection of a bracketed sign change of p on [lo, hi] (p(lo) and p(hi) of
// opposite signs, or p(hi) == 0) down to adjacent doubles.
double bisect(const std::vector<double>& c, double lo, double hi) {
  const bool lo_positive = evaluatePolynomial(c, lo) > 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if ((evaluatePolynomial(c, mid) > 0.0) == lo_positive)
      lo = mid;
    else
      hi = mid;
  }
  return hi;
}

// Breakpoints lo < x_1 < ... < hi between which p is monotonic.
std::vector<double> monotonicPieces(const std::vector<double>& c, double lo, double hi) {
  std::vector<double> points{lo};
  for (double x : realRoots(derivative(c), lo, hi))
    if (x > points.back() && x < hi) points.push_back(x);
  points.push_back(hi);
  return points;
}

}  // namespace

double evaluatePolynomial(const std::vector<double>& coeffs, double x) {
  double v = 0.0;
  for (auto it = coeffs.rbegin(); it != coeffs.rend(); ++it) v = v * x + *it;
  return v;
}

std::vector<double> realRoots(const std::vector<double>& coeffs, double lo, double hi) {
  std::vector<double> c = coeffs;
  while (!c.empty() && c.back() == 0.0) c.pop_back();
  std::vector<double> roots;
  if (c.size() < 2 || !(hi > lo)) return roots;  // constant: no isolated roots
  const std::vector<double> points = monotonicPieces(c, lo, hi);
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const double pa = evaluatePolynomial(c, points[i]);
    const double pb = evaluatePolynomial(c, points[i + 1]);
    if (pb == 0.0)
      roots.push_back(points[i + 1]);
    else if (pa != 0.0 && (pa > 0.0) != (pb > 0.0))
      roots.push_back(bisect(c, points[i], points[i + 1]));
  }
  return roots;
}

double firstNonPositive(const std::vector<double>& coeffs, double hi) {
  std::vector<double> c = coeffs;
  while (!c.empty() && c.back() == 0.0) c.pop_back();
  if (c.size() < 2) return hi;
  const std::vector<double> points = monotonicPieces(c, 0.0, hi);
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    if (evaluatePolynomial(c, points[i + 1]) <= 0.0) {
      // p(points[i]) > 0 (else an earlier piece would have returned).
      return bisect(c, points[i], points[i + 1]);
    }
  }
  return hi;
}

}  // namespace evio::detail
