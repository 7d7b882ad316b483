#include "bsdfs/metallic_roughness.h"

#include <array>

#include "bsdfs/albedo_grid.h"
#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

namespace {

// E(μ, roughness) on nodes μ_j = j/(nMu − 1), roughness_k = k/(nRough − 1). Each node by a
// deterministic 96 × 96 midpoint rule over the sample square of the D(m) cosθm sampler, whose
// estimand f cosθi / pdf = F(wo·m) G1(wo) G1(wi) (wo·m) / (cosθo cosθm) is smooth for every α,
// so the same rule serves the sharp lobes. ~9 M evaluations, once, on first use.
struct AlbedoTable : AlbedoGrid<32, 32> {
  std::array<float, nRough> average;

  AlbedoTable() {
    const int n = 96;
    for (int k = 0; k < nRough; ++k) {
      float roughness = float(k) / (nRough - 1);
      GGX ggx{std::max(roughness * roughness, MetallicRoughness::kMinAlpha)};
      for (int j = 0; j < nMu; ++j) {
        float mu = std::max(float(j) / (nMu - 1), 1e-3f);  // μ = 0 itself is degenerate
        Vec3 wo(std::sqrt(1 - mu * mu), 0.0f, mu);
        double sum = 0;
        for (int a = 0; a < n; ++a)
          for (int b = 0; b < n; ++b) {
            Vec3 m = ggx.sampleNormal(Vec2((a + 0.5f) / n, (b + 0.5f) / n));
            float om = glm::dot(wo, m);
            if (om <= 0) continue;
            Vec3 wi = reflect(wo, m);
            if (wi.z <= 0) continue;
            sum += fresnelSchlick(kDielectricF0, om) * ggx.G1(wo) * ggx.G1(wi) * om / (mu * m.z);
          }
        E[k][j] = float(std::min(1.0, sum / (n * n)));
      }
      // 2∫₀¹ E(μ) μ dμ exactly for E linear between nodes: on [a, b] with E = Ea + s (μ − a),
      // ∫ E μ dμ = Ea (b² − a²)/2 + s ((b³ − a³)/3 − a (b² − a²)/2).
      double avg = 0;
      for (int j = 0; j + 1 < nMu; ++j) {
        double a = double(j) / (nMu - 1), b = double(j + 1) / (nMu - 1);
        double slope = (E[k][j + 1] - E[k][j]) / (b - a);
        avg += E[k][j] * (b * b - a * a) / 2 + slope * ((b * b * b - a * a * a) / 3 - a * (b * b - a * a) / 2);
      }
      average[k] = float(2 * avg);
    }
  }
  static const AlbedoTable& get() {
    static const AlbedoTable table;  // thread-safe initialisation
    return table;
  }
};

}  // namespace

float MetallicRoughness::specularAlbedo(float cosTheta, float roughness) { return AlbedoTable::get()(cosTheta, roughness); }

float MetallicRoughness::specularAlbedoAverage(float roughness) {
  const AlbedoTable& table = AlbedoTable::get();
  int k;
  float tk;
  lerpNodes(roughness, AlbedoTable::nRough, &k, &tk);
  return (1 - tk) * table.average[k] + tk * table.average[k + 1];
}

MetallicRoughness::Point MetallicRoughness::at(const Vec2& uv) const {
  Spectrum mr = metallicRoughness_.evalRGB(uv);
  float roughness = std::clamp(mr.g, 0.0f, 1.0f), metallic = std::clamp(mr.b, 0.0f, 1.0f);
  float transmission = transmits_ ? std::clamp(transmission_.evalRGB(uv).r, 0.0f, 1.0f) : 0.0f;
  return {GGX{std::max(roughness * roughness, kMinAlpha)}, roughness, metallic, transmission};
}

namespace {
Vec3 mirrored(const Vec3& w) { return Vec3(w.x, w.y, -w.z); }  // through the surface plane
}  // namespace

Spectrum MetallicRoughness::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (o.z < 0) o.z = -o.z, i.z = -i.z;  // wo's side as the upper hemisphere
  if (!(o.z > 0) || i.z == 0 || (i.z < 0 && !transmits_)) return Spectrum(0.0f);
  return f(at(c.uv), o, i, c);
}

Spectrum MetallicRoughness::f(const Point& p, const Vec3& o, const Vec3& i, const BSDFContext& c) const {
  const Spectrum rho = baseColor_.eval(c.uv, *c.lambda, c.color);
  if (i.z < 0) {  // thin-walled transmission: the lobe mirrored, times what the layer lets through
    if (p.transmission <= 0 || p.metallic >= 1) return Spectrum(0.0f);
    const Vec3 im = mirrored(i);
    const Vec3 m = glm::normalize(o + im);
    float microfacet = p.ggx.D(m) * p.ggx.G1(o) * p.ggx.G1(im) / (4.0f * o.z * im.z);
    return rho * ((1 - p.metallic) * p.transmission * (1 - fresnelSchlick(kDielectricF0, glm::dot(o, m))) * microfacet);
  }
  Vec3 m = glm::normalize(o + i);
  float om = glm::dot(o, m);
  float microfacet = p.ggx.D(m) * p.ggx.G1(o) * p.ggx.G1(i) / (4.0f * o.z * i.z);
  Spectrum F = (1 - p.metallic) * Spectrum(fresnelSchlick(kDielectricF0, om)) + p.metallic * fresnelSchlick(rho, om);
  Spectrum f = F * microfacet;
  if (p.metallic < 1 && p.transmission < 1) {
    float Eo = specularAlbedo(o.z, p.roughness), Ei = specularAlbedo(i.z, p.roughness);
    float norm = 1 - specularAlbedoAverage(p.roughness);
    if (norm > 0) f += (1 - p.metallic) * (1 - p.transmission) * rho * (kInvPi * (1 - Eo) * (1 - Ei) / norm);
  }
  return f;
}

// Each lobe's share of the sampling: its albedo estimate over the total. The dielectric's
// specular and diffuse ones are exact (E(μo) and ρ(1 − E(μo))); the transmission's is
// approximated by ρ(1 − E(μo)) (exact for the F = 1 lobe's albedo 1); the metal's by the mean of
// its F0, at least 0.04 so a black metal still samples its grazing Fresnel reflection.
MetallicRoughness::LobeProbabilities MetallicRoughness::lobeProbabilities(const Point& p, const BSDFContext& c,
                                                                         float cosThetaO) const {
  Spectrum rho = baseColor_.evalRGB(c.uv) * c.color;
  float mean = (rho.r + rho.g + rho.b) / 3.0f;
  float E = specularAlbedo(cosThetaO, p.roughness);
  float specular = (1 - p.metallic) * E + p.metallic * std::max(mean, kDielectricF0);
  float diffuse = (1 - p.metallic) * (1 - p.transmission) * mean * (1 - E);
  float transmission = (1 - p.metallic) * p.transmission * mean * (1 - E);
  float total = specular + diffuse + transmission;
  if (!(total > 0)) return {1.0f, 0.0f, 0.0f};
  const float ps = specular / total, pt = transmission / total;
  return {ps, 1 - ps - pt, pt};
}

float MetallicRoughness::pdf(const Point& p, const LobeProbabilities& lobes, const Vec3& o, const Vec3& i) const {
  if (i.z < 0) return lobes.transmission > 0 ? lobes.transmission * p.ggx.pdfReflection(o, mirrored(i)) : 0.0f;
  return lobes.specular * p.ggx.pdfReflection(o, i) + lobes.diffuse * pdfCosineHemisphere(i);
}

float MetallicRoughness::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (o.z < 0) o.z = -o.z, i.z = -i.z;
  if (!(o.z > 0) || i.z == 0 || (i.z < 0 && !transmits_)) return 0.0f;
  const Point p = at(c.uv);
  return pdf(p, lobeProbabilities(p, c, o.z), o, i);
}

bool MetallicRoughness::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const {
  Vec3 o;
  if (!upperHemisphere(wo, &o)) return false;
  const Point p = at(c.uv);  // looked up once for the lobe choice, the pdf and f
  const LobeProbabilities lobes = lobeProbabilities(p, c, o.z);
  if (lobes.transmission > 0 && uc >= 1 - lobes.transmission) {
    // Transmission: a reflected direction of the GGX lobe, mirrored to the other side.
    Vec3 wi = reflect(o, p.ggx.sampleNormal(u));
    if (wi.z <= 0) return false;
    wi = mirrored(wi);
    s->pdf = pdf(p, lobes, o, wi);
    if (!(s->pdf > 0)) return false;
    s->weight = f(p, o, wi, c) * (-wi.z / s->pdf);
    if (wo.z < 0) wi.z = -wi.z;
    s->wi = wi;
    s->delta = false;
    return true;
  }
  Vec3 wi = uc < lobes.specular ? reflect(o, p.ggx.sampleNormal(u)) : sampleCosineHemisphere(u);
  if (wi.z <= 0) return false;
  float pdf = lobes.specular * p.ggx.pdfReflection(o, wi) + lobes.diffuse * pdfCosineHemisphere(wi);
  return finishReflectionSample(wo, wi, pdf, [&] { return f(p, o, wi, c); }, s);
}

}  // namespace pl
