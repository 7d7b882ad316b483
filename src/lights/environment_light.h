// Light from infinitely far away in every direction: a sky. Radiance L(ω) is a constant or an
// equirectangular (latitude–longitude) map, W/(m²·sr) per texel in linear RGB.
//
// Map convention (that of Mitsuba 3's `envmap` with its default transform, so a map lights a
// scene the same in both): +Y is up; for the direction ω a ray escapes in, rotated by −rotation
// about +Y, u = atan2(ω_x, −ω_z)/2π (wrapped to [0, 1)) and v = acos(ω_y)/π, with row 0 of the
// image (v = 0) at the zenith. Texels are looked up as boxes (nearest texel), the shape the
// importance sampling below reproduces exactly.
//
// Sampling (next-event estimation, photon emission): a texel with probability ∝ its luminance
// times its solid angle Δω = (2π/W)(cosθ_j − cosθ_{j+1}) (rows by a marginal distribution,
// columns by the row's conditional), then a direction uniformly in solid angle inside it
// (uniform in φ and in cosθ). The density is then p(ω) = Y(texel)/∫Y dω: proportional to the
// luminance, constant inside a texel, 1/4π for a constant sky; Li/p is the same for every
// direction of a texel.
//
// Photons (Φ = πR²·∫L dω): a direction ω by the same distribution, then a point uniformly on the
// disc of the scene's bounding radius R facing it, one radius out; the photon travels along −ω
// carrying L(ω)/(p(ω)·1/πR²). Every line through the bounding sphere crosses that disc, so
// every surface point receives the sky's whole irradiance.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/sampling.h"
#include "lights/light.h"
#include "image/image.h"

namespace pl {

class EnvironmentLight final : public Light {
 public:
  // `map`: linear RGB radiance, row 0 at the zenith, already multiplied by any scale; values
  // must be finite and ≥ 0 (makeEnvironment checks them). `rotation`: degrees about +Y.
  EnvironmentLight(ImageRGB map, float rotationDegrees, std::string description);
  static std::unique_ptr<EnvironmentLight> constant(const Spectrum& radiance);

  Spectrum power() const override { return kPi * radius_ * radius_ * integral_; }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  // y: any point along the direction from p (the sky is at infinity).
  float pdfLi(const Vec3& p, const Vec3& y) const override { return pdf(glm::normalize(y - p)); }
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  // Radiance leaving the sky in direction w (towards the scene): what arrives from −w.
  Spectrum L(const Vec3&, const Vec3& w, const SampledWavelengths& lambda) const override { return radiance(-w, lambda); }
  void preprocess(const Vec3& center, float radius) override;
  const char* name() const override { return "environment"; }

  // Radiance arriving along −d: what a ray escaping the scene in direction d (unit) sees; with
  // `pdf`, also pdf(d) from the same texel lookup.
  Spectrum radiance(const Vec3& d, const SampledWavelengths& lambda, float* pdf = nullptr) const;
  // Solid-angle density of sampleDirection() (and of sampleLi) for the unit direction d.
  float pdf(const Vec3& d) const;
  // A direction towards the sky by the texel distribution; its density in *pdf.
  Vec3 sampleDirection(const Vec2& u, float* pdf) const;
  // ∫ L dω over the sphere (RGB), W/m².
  const Spectrum& integral() const { return integral_; }
  const std::string& description() const { return description_; }
  const ImageRGB& map() const { return map_; }
  // The texel (column, row) the unit direction d falls in, and its centre's direction.
  std::pair<int, int> texel(const Vec3& d) const;

 private:
  Vec3 toLocal(const Vec3& d) const { return Vec3(cos_ * d.x - sin_ * d.z, d.y, sin_ * d.x + cos_ * d.z); }
  Vec3 toWorld(const Vec3& l) const { return Vec3(cos_ * l.x + sin_ * l.z, l.y, -sin_ * l.x + cos_ * l.z); }
  ImageRGB map_;
  float cos_ = 1.0f, sin_ = 0.0f;  // the rotation about +Y
  std::string description_;
  PiecewiseConstant1D rows_;                 // marginal: Σ_i Y_ij·Δω_j
  std::vector<PiecewiseConstant1D> columns_; // per row: Y_ij
  float inverseLuminanceIntegral_ = 0.0f;    // 1/∫Y dω
  Spectrum integral_{0.0f};
  Vec3 center_{0.0f};
  float radius_ = 1.0f;
};

// An environment as a user gives it: `--env R,G,B` (or one number for grey), or `--env
// FILE` with `--env-rotate DEG` and `--env-scale S`; the same in glTF
// (extras.photonlab.environment) and in experiments (env, env_rotate, env_scale).
struct EnvironmentSpec {
  bool enabled = false;
  Spectrum radiance{1.0f};  // the constant sky's radiance, W/(m²·sr) (a named sky's mean), when `map` is empty
  std::string sky;          // a named analytic sky: "overcast" (overcastSky below), or empty
  std::string map;          // an equirectangular image: EXR, HDR or PFM (linear) or PNG/JPEG (sRGB-decoded)
  float rotation = 0.0f;    // degrees about +Y
  float scale = 1.0f;
  std::string describe() const;  // "constant 1, 1, 1 W/(m2 sr)" or "map sky.exr, rotated 90 deg, scale 2"
};

// The sky a scene without any light gets (with a note): the overcast sky of mean radiance
// 1 W/(m²·sr) (`--env 1` is the uniform one).
EnvironmentSpec defaultEnvironment();

// The CIE standard overcast sky (Moon and Spencer 1942; CIE S 011, sky type 1),
// L(θ) = L_z (1 + 2 cosθ)/3 above the horizon, over a grey ground of albedo 0.3 that it lights,
// L_g = 0.3 E/π = (0.7/3) L_z, scaled so that its mean over the sphere is `mean`. Brighter
// overhead than at the horizon and darker below, it shades a model's tops and undersides apart
// and gives glossy surfaces a horizon to reflect, where a uniform sky shows neither. `rows` rows
// of constant θ, one texel wide (it does not vary with φ), each the exact mean of L over its band.
ImageRGB overcastSky(const Spectrum& mean, int rows = 256);

// "R,G,B" or "L" (radiance) or a file name: what --env takes. Throws Error naming `field` on a
// negative or non-finite number.
EnvironmentSpec parseEnvironment(const std::string& text, const std::string& field);

// Reads an image file as linear RGB (the io layer's, or a test's); throws Error naming the file.
using ImageReader = std::function<ImageRGB(const std::string& path)>;
// The light for a spec; a map is read by `read` and checked (finite, ≥ 0, not all black), errors
// name `field`.
std::unique_ptr<EnvironmentLight> makeEnvironment(const EnvironmentSpec& spec, const ImageReader& read,
                                                  const std::string& field);

}  // namespace pl
