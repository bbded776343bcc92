#pragma once
/// @file chi_squared.h
/// The χ² distribution for gating (MSCKF, SLAM) and consistency bounds (NEES).
/// Boost is not a dependency: the CDF is the regularised lower incomplete
/// gamma function P(k/2, x/2), evaluated by its power series for x < a + 1 and
/// by a continued fraction otherwise; the quantile inverts it by safeguarded
/// Newton iteration (bisection fallback) to a relative accuracy of 1e-12.

namespace evio::estimator {

/// Regularised lower incomplete gamma P(a, x) = γ(a, x)/Γ(a), a > 0, x >= 0.
double regularizedGammaP(double a, double x);

/// CDF of the χ² distribution with `dof` degrees of freedom at x (0 for x <= 0).
double chi2Cdf(double x, double dof);

/// Quantile: the x with chi2Cdf(x, dof) = p, for 0 < p < 1 and dof > 0.
/// Throws evio::Error for arguments outside that domain.
double chi2Quantile(double p, double dof);

/// Cached chi2Quantile(p, dof) for integer dof in [1, 1000] and a fixed p
/// (a gate evaluates the same quantile thousands of times a second).
class Chi2Table {
 public:
  explicit Chi2Table(double probability);
  double probability() const { return p_; }
  /// chi2Quantile(probability(), dof); dof >= 1 (computed directly above 1000).
  double operator()(int dof) const;

 private:
  double p_;
  double table_[1001];
};

}  // namespace evio::estimator
