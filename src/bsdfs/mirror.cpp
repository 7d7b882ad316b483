#include "bsdfs/mirror.h"

#include "optics/optics.h"

namespace pl {

bool Mirror::sample(const Vec3& wo, const BSDFContext& c, const Vec2&, float, BSDFSample* s) const {
  if (wo.z == 0) return false;
  s->wi = reflect(wo, Vec3(0, 0, wo.z > 0 ? 1.0f : -1.0f));
  s->weight = fresnelSchlick(F0_.eval(c.uv, *c.lambda, c.color), wo.z);
  s->pdf = 1.0f;
  s->delta = true;
  return true;
}

}  // namespace pl
