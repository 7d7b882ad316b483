// The GGX (Trowbridge–Reitz) microfacet distribution shared by the rough BSDFs (Walter et al.
// 2007): D(m) = α² / (π (cos²θm (α² − 1) + 1)²), separable Smith G = G1(wo) G1(wi), sampled
// by D(m) cosθm. All vectors in the shading frame, on the upper side (z > 0).
#pragma once
#include <algorithm>
#include <cmath>

#include "core/common.h"
#include "core/sampling.h"

namespace pl {

struct GGX {
  float alpha;  // glTF: α = roughness²

  float D(const Vec3& m) const {
    if (m.z <= 0) return 0.0f;
    float a2 = alpha * alpha;
    float d = m.z * m.z * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
  }
  float G1(const Vec3& v) const {
    float cos2 = v.z * v.z;
    if (cos2 <= 0) return 0.0f;
    float tan2 = std::max(0.0f, 1.0f - cos2) / cos2;
    return 2.0f / (1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
  }
  // Density of the reflected direction wi = reflect(wo, m) when m is drawn from D(m) cosθm:
  // the reflection Jacobian dωm/dωi = 1 / (4 |wo·m|).
  float pdfReflection(const Vec3& wo, const Vec3& wi) const {
    Vec3 m = glm::normalize(wo + wi);
    return D(m) * m.z / (4.0f * std::abs(glm::dot(wo, m)));
  }
  // A microfacet normal from D(m) cosθm by inverting its CDF: tan²θm = α² u / (1 − u).
  Vec3 sampleNormal(const Vec2& u) const {
    float tan2 = alpha * alpha * u.x / (1.0f - u.x);
    float cosThetaM = 1.0f / std::sqrt(1.0f + tan2);
    float sinThetaM = std::sqrt(std::max(0.0f, 1.0f - cosThetaM * cosThetaM));
    Vec2 sc = sinCos2Pi(u.y);
    return Vec3(sinThetaM * sc.y, sinThetaM * sc.x, cosThetaM);
  }
};

}  // namespace pl
