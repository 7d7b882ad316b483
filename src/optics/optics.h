// Geometric optics as the course notes derive them. Directions point *away* from the surface
// (L towards the light, N the normal), so reflection is R = 2(N·L)N − L.
#pragma once
#include "core/common.h"

namespace pl {

inline Vec3 reflect(const Vec3& L, const Vec3& N) { return 2.0f * glm::dot(N, L) * N - L; }

// Snell's law η_i sinθ_i = η_t sinθ_t with eta = η_t/η_i (relative index).
// `wi` points away from the surface on the side of `n`. Returns false on total internal
// reflection (sin²θ_t > 1), else writes the transmitted direction (unit, opposite side).
inline bool refract(const Vec3& wi, const Vec3& n, float eta, Vec3* wt) {
  float cosThetaI = glm::dot(n, wi);
  float sin2ThetaI = std::max(0.0f, 1.0f - cosThetaI * cosThetaI);
  float sin2ThetaT = sin2ThetaI / (eta * eta);
  if (sin2ThetaT >= 1.0f) return false;
  float cosThetaT = std::sqrt(1.0f - sin2ThetaT);
  *wt = -wi / eta + (cosThetaI / eta - cosThetaT) * n;
  return true;
}

// Exact unpolarised Fresnel reflectance of a dielectric interface. cosThetaI is measured on the
// incident side; eta = η_t/η_i. cosThetaI < 0 means we arrive from the other side: swap media.
inline float fresnelDielectric(float cosThetaI, float eta) {
  if (cosThetaI < 0) {
    eta = 1.0f / eta;
    cosThetaI = -cosThetaI;
  }
  float sin2ThetaT = (1.0f - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2ThetaT >= 1.0f) return 1.0f;  // total internal reflection
  float cosThetaT = std::sqrt(1.0f - sin2ThetaT);
  float rs = (cosThetaI - eta * cosThetaT) / (cosThetaI + eta * cosThetaT);  // s-polarised
  float rp = (eta * cosThetaI - cosThetaT) / (eta * cosThetaI + cosThetaT);  // p-polarised
  return 0.5f * (rs * rs + rp * rp);
}

// glTF's dielectric: (η − 1)² / (η + 1)² for η = 1.5.
constexpr float kDielectricF0 = 0.04f;

// Schlick's approximation F = F0 + (1 − F0)(1 − cosθ)⁵, per channel (metals: F0 = baseColor).
inline float fresnelSchlick(float F0, float cosTheta) {
  float m = std::clamp(1.0f - std::abs(cosTheta), 0.0f, 1.0f);
  return F0 + (1.0f - F0) * (m * m) * (m * m) * m;
}
inline Spectrum fresnelSchlick(const Spectrum& F0, float cosTheta) {
  float m = std::clamp(1.0f - std::abs(cosTheta), 0.0f, 1.0f);
  float m5 = (m * m) * (m * m) * m;
  return F0 + (Spectrum(1.0f) - F0) * m5;
}

}  // namespace pl
