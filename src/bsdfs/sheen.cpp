#include "bsdfs/sheen.h"

#include <algorithm>
#include <cmath>

#include "bsdfs/albedo_grid.h"
#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

namespace {

float alphaOf(float roughness) { return std::max(roughness * roughness, Sheen::kMinAlpha); }

float charlieD(float alpha, float cosThetaM) {
  const float sin2 = std::max(0.0f, 1.0f - cosThetaM * cosThetaM);
  return (2.0f + 1.0f / alpha) * std::pow(sin2, 0.5f / alpha) * (0.5f * kInvPi);
}

float ashikhminV(float cosThetaO, float cosThetaI) { return 1.0f / (4.0f * (cosThetaI + cosThetaO - cosThetaI * cosThetaO)); }

// E(μ, roughness) on nodes μ_j = j/(nMu − 1) (μ_0 = 10⁻³), roughness_k = k/(nRough − 1). Each node
// by a deterministic n × n midpoint rule over the sample square of m drawn from D(m) cosθm
// (sinθm = u^(α/(1 + 2α))), whose estimand f cosθi / pdf = 4 V cosθi (wo·m) / cosθm has D
// cancelled and stays bounded (cosθi < 2 (wo·m) cosθm), so the same rule serves every α.
struct SheenTable : AlbedoGrid<32, 32> {
  static constexpr int n = 128;

  SheenTable() {
    for (int k = 0; k < nRough; ++k) {
      const double alpha = alphaOf(float(k) / (nRough - 1));
      for (int j = 0; j < nMu; ++j) {
        const double mu = std::max(double(j) / (nMu - 1), 1e-3);
        const double so = std::sqrt(1 - mu * mu);
        double sum = 0;
        for (int a = 0; a < n; ++a) {
          const double sinM = std::pow((a + 0.5) / n, alpha / (1 + 2 * alpha));
          const double cosM = std::sqrt(std::max(0.0, 1 - sinM * sinM));
          for (int b = 0; b < n; ++b) {
            const double phi = 2 * M_PI * (b + 0.5) / n;
            const double om = so * sinM * std::cos(phi) + mu * cosM;  // wo·m, wo = (so, 0, μ)
            if (om <= 0 || cosM <= 0) continue;
            const double ci = 2 * om * cosM - mu;  // (reflect(wo, m)).z
            if (ci <= 0) continue;
            sum += 4 * ci * om / (4 * (ci + mu - ci * mu) * cosM);
          }
        }
        E[k][j] = float(sum / (n * n));
      }
    }
  }
  static const SheenTable& get() {
    static const SheenTable table;  // thread-safe initialisation
    return table;
  }
};

}  // namespace

float Sheen::lobeAlbedo(float cosTheta, float roughness) { return SheenTable::get()(cosTheta, roughness); }

float Sheen::roughness(const Vec2& uv) const { return std::clamp(roughness_.eval(uv), 0.0f, 1.0f); }

Spectrum Sheen::eval(const Vec3& o, const Vec3& i, const BSDFContext& c) const {
  const float r = roughness(c.uv);
  const Vec3 m = glm::normalize(o + i);
  const float scale = std::max({1.0f, lobeAlbedo(o.z, r), lobeAlbedo(i.z, r)});
  return color_.eval(c.uv, *c.lambda) * (charlieD(alphaOf(r), m.z) * ashikhminV(o.z, i.z) / scale);
}

float Sheen::pdf(const Vec3&, const Vec3& i, const BSDFContext&) const { return pdfCosineHemisphere(i); }

Vec3 Sheen::sample(const Vec3&, const BSDFContext&, const Vec2& u) const { return sampleCosineHemisphere(u); }

float Sheen::albedo(float mu, const BSDFContext& c) const {
  const Spectrum color = color_.evalRGB(c.uv);
  const float peak = std::max({color.r, color.g, color.b});
  return peak > 0 ? peak * std::min(1.0f, lobeAlbedo(mu, roughness(c.uv))) : 0.0f;
}

}  // namespace pl
