// Statistical helpers for tests: the chi-square goodness-of-fit test used to check that a
// sampler draws directions with the density its pdf() claims (as in Nori and Mitsuba).
#pragma once
#include <cmath>
#include <functional>
#include <vector>

namespace pl::test {

// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes §6.2).
inline double gammaQ(double a, double x) {
  if (x <= 0) return 1.0;
  double gln = std::lgamma(a);
  if (x < a + 1) {  // series for P
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 1000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;  // continued fraction for Q
  for (int i = 1; i < 1000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// Pearson's test of observed counts against expected counts. Cells expecting fewer than 5
// are pooled. Returns the p-value of the null hypothesis "the sampler matches".
inline double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi2 = 0, pooledObs = 0, pooledExp = 0;
  int dof = -1;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5) {
      pooledObs += observed[i];
      pooledExp += expected[i];
    } else {
      double d = observed[i] - expected[i];
      chi2 += d * d / expected[i];
      ++dof;
    }
  }
  if (pooledExp > 0) {
    double d = pooledObs - pooledExp;
    chi2 += d * d / std::max(pooledExp, 5.0);
    ++dof;
  }
  if (dof < 1) return 1.0;
  return gammaQ(dof / 2.0, chi2 / 2.0);
}

}  // namespace pl::test
