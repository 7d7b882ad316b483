#include "bsdfs/layered.h"

#include <algorithm>

namespace pl {

namespace {
Vec3 flipped(const Vec3& w) { return Vec3(w.x, w.y, -w.z); }
}  // namespace

Layered::Layered(std::unique_ptr<BSDF> base, std::unique_ptr<BSDFLayer> layer)
    : BSDF(base->flags() | kGlossyReflection), base_(std::move(base)), layer_(std::move(layer)),
      name_(std::string(layer_->name()) + " over " + base_->name()) {}

float Layered::baseWeight(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  const float a = std::max(layer_->albedo(std::abs(wo.z), c), layer_->albedo(std::abs(wi.z), c));
  return std::clamp(1.0f - a, 0.0f, 1.0f);
}

Spectrum Layered::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  if (wo.z == 0 || wi.z == 0) return Spectrum(0.0f);
  Spectrum f = base_->eval(wo, wi, c) * baseWeight(wo, wi, c);
  if ((wo.z > 0) == (wi.z > 0)) f += wo.z > 0 ? layer_->eval(wo, wi, c) : layer_->eval(flipped(wo), flipped(wi), c);
  return f;
}

float Layered::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  if (wo.z == 0 || wi.z == 0) return 0.0f;
  const float P = std::min(layer_->albedo(std::abs(wo.z), c), 1.0f);
  float pdf = (1 - P) * base_->pdf(wo, wi, c);
  if (P > 0 && (wo.z > 0) == (wi.z > 0)) pdf += P * (wo.z > 0 ? layer_->pdf(wo, wi, c) : layer_->pdf(flipped(wo), flipped(wi), c));
  return pdf;
}

bool Layered::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const {
  if (wo.z == 0) return false;
  const float P = std::min(layer_->albedo(std::abs(wo.z), c), 1.0f);
  Vec3 wi;
  if (uc < P) {
    const Vec3 i = layer_->sample(wo.z > 0 ? wo : flipped(wo), c, u);
    if (!(i.z > 0)) return false;
    wi = wo.z > 0 ? i : flipped(i);
  } else {
    // The base's own lobe choice from what is left of uc, rescaled to [0, 1).
    const float ub = P > 0 ? std::min((uc - P) / (1 - P), 0x1.fffffep-1f) : uc;
    BSDFSample b;
    if (!base_->sample(wo, c, u, ub, &b)) return false;
    if (b.delta) {  // the layer has no delta lobe: the base's alone, seen through the layer
      *s = b;
      s->pdf *= 1 - P;
      s->weight *= baseWeight(wo, b.wi, c) / (1 - P);
      return true;
    }
    wi = b.wi;
  }
  s->pdf = pdf(wo, wi, c);
  if (!(s->pdf > 0)) return false;
  s->weight = eval(wo, wi, c) * (std::abs(wi.z) / s->pdf);
  s->wi = wi;
  s->delta = false;
  s->eta = 1.0f;
  s->terminatesSecondary = false;
  return true;
}

bool Layered::specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const {
  if (!base_->specularLobe(wo, c, lobe, s)) return false;
  s->weight *= baseWeight(wo, s->wi, c);
  return true;
}

}  // namespace pl
