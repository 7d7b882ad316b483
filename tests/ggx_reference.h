// The GGX microfacet formulas written out independently of src/bsdfs/ggx.h (Walter et al. 2007),
// and the albedos of glTF's dielectric specular layer computed from them by quadrature: the
// expected values of the metallic-roughness and thin-walled transmission tests.
#pragma once
#include <cmath>

#include "core/common.h"

namespace pl::test {

inline double ggxD(double cosM, double alpha) {
  if (cosM <= 0) return 0;
  double a2 = alpha * alpha, d = cosM * cosM * (a2 - 1) + 1;
  return a2 / (kPi * d * d);
}
inline double ggxG1(double cosV, double alpha) {
  double c2 = cosV * cosV, tan2 = (1 - c2) / c2;
  return 2 / (1 + std::sqrt(1 + alpha * alpha * tan2));
}
inline double schlick004(double cosTheta) { return 0.04 + 0.96 * std::pow(1 - std::abs(cosTheta), 5); }

// ∫ F(o·m) D(m) G1(o) G1(i) / (4 μo μi) μi dωi over the upper hemisphere, F = 1 or Schlick's
// with F0 = 0.04, by the midpoint rule on n × n cells of (cosθi, φ); wo = (sinθo, 0, μo).
inline double lobeAlbedo(double mu, double alpha, bool schlick, int n = 400) {
  const glm::dvec3 o(std::sqrt(1 - mu * mu), 0.0, mu);
  double sum = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      double ci = (a + 0.5) / n, phi = 2 * kPi * (b + 0.5) / n, si = std::sqrt(1 - ci * ci);
      glm::dvec3 i(si * std::cos(phi), si * std::sin(phi), ci);
      glm::dvec3 m = glm::normalize(o + i);
      double F = schlick ? schlick004(glm::dot(o, m)) : 1.0;
      sum += F * ggxD(m.z, alpha) * ggxG1(mu, alpha) * ggxG1(ci, alpha) / (4 * mu * ci) * ci;
    }
  return sum * (1.0 / n) * (2 * kPi / n);
}

}  // namespace pl::test
