// The BSDF interface. All directions are in the local shading frame (z = shading normal) and
// point away from the surface: wo towards the viewer (or where light leaves), wi towards the
// light. eval() is f(wo, wi) without the cosine; sample() returns the Monte Carlo weight
// f·|cosθi|/pdf so that an estimator multiplies by it directly.
#pragma once
#include "core/common.h"
#include "spectral/spectral.h"

namespace pl {

// Radiance is transported from lights to eye paths, importance (photons' flux) the other way.
// Refraction compresses radiance by 1/η² but not flux, so the two modes differ there.
enum class TransportMode { Radiance, Importance };

// Where and how a BSDF is evaluated: the texture coordinates, the vertex colour (glTF COLOR_0,
// linear RGB: it multiplies the base colour), the path's wavelengths and the quantity
// transported. From a bare uv: white, RGB and radiance (tests). At a surface point:
// bsdfContext(hit, ...) in scene/scene.h.
struct BSDFContext {
  Vec2 uv{0.0f};
  const SampledWavelengths* lambda = &SampledWavelengths::rgb();
  TransportMode mode = TransportMode::Radiance;
  Spectrum color{1.0f};

  BSDFContext() = default;
  BSDFContext(const Vec2& uv) : uv(uv) {}  // NOLINT: implicit on purpose
  BSDFContext(const Vec2& uv, const SampledWavelengths& lambda, TransportMode mode = TransportMode::Radiance,
              const Spectrum& color = Spectrum(1.0f))
      : uv(uv), lambda(&lambda), mode(mode), color(color) {}
};

struct BSDFSample {
  Vec3 wi;
  Spectrum weight;   // f·|cosθi| / pdf
  float pdf = 0.0f;  // solid angle; for delta lobes the discrete probability of the lobe
  bool delta = false;
  float eta = 1.0f;  // η_t/η_i of a refraction (what radiance's 1/η² scaling came from); 1 otherwise
  // A dispersive refraction: the caller's path follows the hero wavelength alone from here on
  // (SampledWavelengths::terminateSecondary); `weight` already holds the hero's ×3.
  bool terminatesSecondary = false;
};

// What a BSDF's lobes are, one bit per kind of lobe (Mitsuba 3's BSDFFlags; pbrt-v4's BxDFFlags
// as a union): integrators ask these instead of probing sample() or testing the class.
enum BSDFFlags : uint8_t {
  kNoLobe = 0,
  kDiffuseReflection = 1 << 0,
  kGlossyReflection = 1 << 1,
  kSpecularReflection = 1 << 2,  // a Dirac delta: only sample() finds it
  kDiffuseTransmission = 1 << 3,
  kGlossyTransmission = 1 << 4,
  kSpecularTransmission = 1 << 5,
  kReflection = kDiffuseReflection | kGlossyReflection | kSpecularReflection,
  kTransmission = kDiffuseTransmission | kGlossyTransmission | kSpecularTransmission,
  kSpecular = kSpecularReflection | kSpecularTransmission,
  kSmooth = kDiffuseReflection | kGlossyReflection | kDiffuseTransmission | kGlossyTransmission,  // eval() sees them
};
constexpr BSDFFlags operator|(BSDFFlags a, BSDFFlags b) { return BSDFFlags(uint8_t(a) | uint8_t(b)); }
// Every lobe a Dirac delta (mirror, smooth glass): eval and pdf are zero, no light sample can
// be weighed against it, and density estimation there is meaningless.
constexpr bool isSpecular(BSDFFlags f) { return f != kNoLobe && (f & kSmooth) == 0; }
// A lobe eval() sees that transmits (wo and wi on opposite sides: a thin translucent wall):
// estimators that gather light on one side of a surface (photon density estimation) then gather
// it from both.
constexpr bool hasGlossy(BSDFFlags f) { return (f & (kGlossyReflection | kGlossyTransmission)) != 0; }
constexpr bool hasSmoothTransmission(BSDFFlags f) { return (f & (kDiffuseTransmission | kGlossyTransmission)) != 0; }

// The few classes that accelerators specialise on (pbrt-v4 dispatches on a TaggedPointer's tag
// the same way): the path tracer's SIMD lanes, the photon tracer's inlined diffuse bounce and
// radiosity read them; every other BSDF is kOther, and integrators use the flags alone.
enum class BSDFClass : uint8_t { kOther, kLambertian, kMirror, kDielectric };

// f(wo, wi) with the solid-angle densities of sampling wi from wo (pdf) and wo from wi
// (pdfReverse; zero unless asked for): BSDF::evaluate.
struct BSDFEval {
  Spectrum f{0.0f};
  float pdf = 0.0f, pdfReverse = 0.0f;
};

class BSDF {
 public:
  virtual ~BSDF() = default;
  virtual Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const = 0;
  virtual float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const = 0;
  // eval(wo, wi), pdf(wo, wi) and, with `reverse`, pdf(wi, wo), the same numbers bit for bit, in
  // one call: MIS needs f and its densities together (bidirectional MIS both ways; Mitsuba 3's
  // eval_pdf is the same idea), and a BSDF that overrides this computes their shared terms
  // once (a Phong lobe's power) behind one virtual call instead of three.
  virtual BSDFEval evaluate(const Vec3& wo, const Vec3& wi, const BSDFContext& c, bool reverse) const {
    BSDFEval e;
    e.f = eval(wo, wi, c);
    e.pdf = pdf(wo, wi, c);
    if (reverse) e.pdfReverse = pdf(wi, wo, c);
    return e;
  }
  // u: 2D sample for the direction, uc: 1D sample for choosing a lobe.
  virtual bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const = 0;
  // A specular BSDF's lobe `lobe` (kSpecularReflection or kSpecularTransmission) at wo: what
  // sample() returns when it picks that lobe, so that weight·pdf is the lobe's whole
  // contribution (Whitted's recursion follows every lobe). False when the BSDF has no such lobe
  // or it has probability zero at wo (total internal reflection).
  virtual bool specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const { return false; }
  virtual const char* name() const = 0;
  BSDFFlags flags() const { return flags_; }
  bool isSpecular() const { return pl::isSpecular(flags_); }
  BSDFClass bsdfClass() const { return class_; }

 protected:
  explicit BSDF(BSDFFlags flags, BSDFClass bsdfClass = BSDFClass::kOther) : flags_(flags), class_(bsdfClass) {}

 private:
  // Fixed at construction, read without a virtual call on every bounce.
  BSDFFlags flags_;
  BSDFClass class_;
};

// Veach's adjoint correction for shading normals (Veach 1997, §5.3; pbrt-v3 §16.1): a BSDF
// evaluated with an interpolated shading normal is not symmetric for importance. Light paths
// (TransportMode::Importance) scattered from wo (towards the light side) into wi multiply f·|cos|
// by |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|); ngLocal is the geometric normal in the shading frame
// (ns = z). Radiance needs none: returns 1.
inline float shadingNormalCorrection(const Vec3& wo, const Vec3& wi, const Vec3& ngLocal, TransportMode mode) {
  if (mode == TransportMode::Radiance) return 1.0f;
  float denominator = std::abs(glm::dot(wo, ngLocal)) * std::abs(wi.z);
  return denominator > 0 ? std::abs(wo.z) * std::abs(glm::dot(wi, ngLocal)) / denominator : 0.0f;
}

// Density estimation with shading normals: the photons (or light vertices) within r of a point
// measure flux per unit of geometric area, ∫ Li |wi·ng| dω, while the reflection equation
// integrates Li |wi·ns| dω; each photon's f is therefore weighted by |wi·ns| / |wi·ng| (wi in the
// shading frame, ns = z; ngLocal the geometric normal there). Without it a photon map is too
// bright or too dark wherever normals are interpolated or mapped (tests/test_light_transport.cpp).
// The weight's mean is finite but its variance is not (photons arrive with density ∝ |wi·ng|, so
// E[weight²] ∝ ∫ |wi·ns|²/|wi·ng| dω diverges at grazing incidence), and a tessellated sphere's
// furnace showed it pixel by pixel. It is clamped at 10, which changes only photons with
// |wi·ng| < |wi·ns|/10: for interpolated normals δ off the face normal a solid angle of O(δ/10)
// around the horizon, a bias of O(δ²/10) of the level.
constexpr float kMaxDensityShadingCorrection = 10.0f;
inline float densityShadingCorrection(const Vec3& wiLocal, const Vec3& ngLocal) {
  float d = std::abs(glm::dot(wiLocal, ngLocal));
  return std::abs(wiLocal.z) < kMaxDensityShadingCorrection * d ? std::abs(wiLocal.z) / d : kMaxDensityShadingCorrection;
}

// Reflection-only BSDFs reflect from both sides: evaluate on the side wo is on.
inline bool flipToUpperHemisphere(Vec3& wo, Vec3& wi) {
  if (wo.z < 0) {
    wo.z = -wo.z;
    wi.z = -wi.z;
  }
  return wo.z > 0 && wi.z > 0;
}

// The reflection-only BSDFs sample on wo's side taken as the upper hemisphere. This gives that
// side's wo (z > 0); false when wo lies in the surface.
inline bool upperHemisphere(const Vec3& wo, Vec3* o) {
  *o = Vec3(wo.x, wo.y, std::abs(wo.z));
  return wo.z != 0;
}

// The end of their sample(): wi was drawn in the upper hemisphere with density pdf; the weight
// is f·cosθi/pdf (f() evaluated only for a usable pdf), and wi goes back to wo's side.
template <typename F>
bool finishReflectionSample(const Vec3& wo, Vec3 wi, float pdf, F&& f, BSDFSample* s) {
  s->pdf = pdf;
  if (!(pdf > 0)) return false;
  s->weight = f() * wi.z / pdf;
  if (wo.z < 0) wi.z = -wi.z;
  s->wi = wi;
  s->delta = false;
  return true;
}

}  // namespace pl
