#pragma once
/// @file polynomial_roots.h
/// (private to core/src/camera) Real-root isolation for the low-degree
/// polynomials that bound the valid region of the distortion models.

#include <vector>

namespace evio::detail {

/// p(x) = c[0] + c[1] x + c[2] x² + ... (Horner).
double evaluatePolynomial(const std::vector<double>& coeffs, double x);

/// All sign changes of p in (lo, hi], sorted. Roots are isolated by the
/// roots of p' (found recursively), so inside each piece p is monotonic and
/// a sign change is bracketed and bisected to full double precision. A root
/// where p touches zero without changing sign is reported only if p is
/// exactly 0 there.
std::vector<double> realRoots(const std::vector<double>& coeffs, double lo, double hi);

/// The smallest x in (0, hi] with p(x) <= 0, given p(0) > 0; hi if none.
double firstNonPositive(const std::vector<double>& coeffs, double hi);

}  // namespace evio::detail
