#include "evio/estimator/backend/chi_squared.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "evio/core/error.h"

namespace evio::estimator {
namespace {

constexpr double kEps = 1e-16;
constexpr int kMaxTerms = 100000;

// Series: P(a, x) = e^{-x} x^a / Γ(a) · Σ_n x^n / (a (a+1) ... (a+n)).
double gammaSeries(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxTerms; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction for Q(a, x) = 1 - P(a, x) (modified Lentz):
//   Q = e^{-x} x^a / Γ(a) · 1/(x+1-a- 1·(1-a)/(x+3-a- 2·(2-a)/(x+5-a- ...))).
double gammaContinuedFractionQ(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxTerms; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double regularizedGammaP(double a, double x) {
  require(a > 0.0 && std::isfinite(a), "regularizedGammaP: a must be finite and > 0");
  if (!(x > 0.0)) return 0.0;
  if (std::isinf(x)) return 1.0;
  if (x < a + 1.0) return gammaSeries(a, x);
  return 1.0 - gammaContinuedFractionQ(a, x);
}

double chi2Cdf(double x, double dof) { return x <= 0.0 ? 0.0 : regularizedGammaP(0.5 * dof, 0.5 * x); }

double chi2Quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0) || !std::isfinite(dof))
    throw Error("chi2Quantile: need 0 < p < 1 and dof > 0 (got p=" + std::to_string(p) +
                ", dof=" + std::to_string(dof) + ")");
  // Wilson–Hilferty start: x ≈ k (1 - 2/(9k) + z sqrt(2/(9k)))³, z the normal
  // quantile (Acklam-free rational approximation is enough for a start).
  const double t = std::sqrt(-2.0 * std::log(p < 0.5 ? p : 1.0 - p));
  double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                     (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  if (p < 0.5) z = -z;
  const double h = 2.0 / (9.0 * dof);
  double x = dof * std::pow(std::max(1.0 - h + z * std::sqrt(h), 0.05), 3);
  // Bracket [lo, hi] and refine with Newton steps, bisecting when a step leaves it.
  double lo = 0.0, hi = std::max(2.0 * x, dof + 40.0 * std::sqrt(2.0 * dof) + 100.0);
  while (chi2Cdf(hi, dof) < p) hi *= 2.0;
  const double a = 0.5 * dof;
  for (int it = 0; it < 200; ++it) {
    const double f = chi2Cdf(x, dof) - p;
    if (f < 0.0) lo = x; else hi = x;
    // pdf(x) = x^{a-1} e^{-x/2} / (2^a Γ(a))
    const double pdf = std::exp((a - 1.0) * std::log(x) - 0.5 * x - a * std::log(2.0) - std::lgamma(a));
    double next = (pdf > 0.0 && std::isfinite(pdf)) ? x - f / pdf : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-13 * std::max(1.0, x)) return next;
    x = next;
  }
  return x;
}

Chi2Table::Chi2Table(double probability) : p_(probability) {
  table_[0] = 0.0;
  for (int k = 1; k <= 1000; ++k) table_[k] = chi2Quantile(p_, k);
}

double Chi2Table::operator()(int dof) const {
  require(dof >= 1, "Chi2Table: dof must be >= 1");
  return dof <= 1000 ? table_[dof] : chi2Quantile(p_, dof);
}

}  // namespace evio::estimator
