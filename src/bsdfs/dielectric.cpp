#include "bsdfs/dielectric.h"

#include "optics/optics.h"

namespace pl {

bool Dielectric::sample(const Vec3& wo, const Vec2&, const Vec2&, float uc, TransportMode mode,
                        BSDFSample* s) const {
  if (wo.z == 0) return false;
  float F = fresnelDielectric(wo.z, eta_);
  s->delta = true;
  if (uc < F) {
    // Reflection chosen with probability F: weight F/F = 1.
    s->wi = Vec3(-wo.x, -wo.y, wo.z);
    s->weight = Spectrum(1.0f);
    s->pdf = F;
    return true;
  }
  bool entering = wo.z > 0;
  float etaRel = entering ? eta_ : 1.0f / eta_;  // η_t/η_i
  Vec3 n(0, 0, entering ? 1.0f : -1.0f);
  if (!refract(wo, n, etaRel, &s->wi)) return false;  // cannot happen when F < 1
  // Radiance is compressed by (η_i/η_t)² crossing into the denser medium (pbrt §8.2);
  // flux carried by photons is not.
  float scale = mode == TransportMode::Radiance ? 1.0f / (etaRel * etaRel) : 1.0f;
  s->weight = Spectrum(scale);
  s->pdf = 1.0f - F;
  return true;
}

}  // namespace pl
