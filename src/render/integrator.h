// The integrator interface: an integrator renders the whole image and owns its loop (as
// pbrt-v4's Integrator::Render). Three shared loops hold the parts every algorithm repeats (keyed
// random streams, camera samples, wavelengths, budget, checkpoints, the film):
//   PixelIntegrator  camera-side, one radiance estimate Li per pixel sample (render/renderer.h),
//                    with a training hook between iterations for integrators that learn;
//   PassIntegrator   eye passes and photon passes alternating (integrators/progressive.h);
//   light-side       light paths splatted onto the film (render/light_loop.h).
// Each integrator registers itself, with its parameters, in its own file (integrators/registry.h).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/budget.h"
#include "core/rng.h"
#include "core/sampler.h"
#include "render/film.h"
#include "render/render_options.h"
#include "scene/scene.h"

namespace pl {

// An image an integrator makes beside its radiance (e.g. bdpt's one image per technique); the
// CLI writes it next to the output as OUT.<name>.ext.
struct NamedImage {
  std::string name;
  ImageRGB image;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Deterministic for options.seed whatever options.threads is; stops early when the time
  // budget ends or on an interrupt (info says which).
  virtual ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) = 0;
  virtual const char* name() const = 0;
  // Things the user should know (e.g. "no photons were stored"), printed by the CLI.
  virtual std::vector<std::string> warnings() const { return {}; }
  // What the render did that a summary line has no room for (radiosity's patch count, solve
  // time), printed by the CLI after it as "NAME: note".
  virtual std::vector<std::string> notes() const { return {}; }
  // Images beside the radiance, after render().
  virtual std::vector<NamedImage> extraImages() const { return {}; }
};

// Integrators that learn as they render (path guiding) render in iterations, each some passes
// over the image with what was learned before it, so that each is an unbiased image on its own;
// the pixel loop combines them by inverse variance (render/iteration_film.h) and calls the
// integrator's training hook between them (PixelIntegrator::training()).
struct Iteration {
  int samples = 0;        // passes (samples per pixel); 0 ends the render
  bool last = false;      // nothing will be learned after it
  bool replaces = false;  // its image takes the place of the iterations' before it
};
// What the pixel loop measured of an iteration that ended.
struct IterationReport {
  int samples = 0;               // the passes it asked for
  int least = 0;                 // the samples every pixel got (fewer where the budget cut it short)
  double trainingSeconds = 0;    // the hook's time before its passes
  double seconds = 0;            // training and passes together
  double elapsed = 0;            // the render's time when it ended
  double variance = 0;           // σ² of one sample (channel mean), pooled over the image
  double relativeVariance = 0;   // each pixel's σ² over its value² + 0.01, averaged (relMSE's weighting)
};
class TrainingHook {
 public:
  virtual ~TrainingHook() = default;
  // Before iteration `index` (0, 1, ...): learn from what the passes before recorded, and say
  // how the next iteration runs. `options` has the resolution resolved; polls the budget.
  virtual Iteration beforeIteration(const Scene& scene, int index, const RenderOptions& options, int threads,
                                    const Budget& budget) = 0;
  virtual void afterIteration(const IterationReport& report) = 0;
};

// Camera-side integrators: the pixel value is the mean of Li over the pixel's samples (over
// each iteration's, combined, where the integrator learns between iterations).
class PixelIntegrator : public Integrator {
 public:
  // Work done once before the first sample (photon tracing). Deterministic for a seed. It polls
  // the render's budget: when that expires the render stops, whatever preprocess() has left.
  virtual void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) {}
  // Radiance arriving along a camera ray, at the path's wavelengths (RGB unless spectral). A
  // dispersive refraction on the way ends the secondary wavelengths in `lambda`.
  virtual Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const = 0;
  // Li for n ≤ packetSize() camera samples at once (neighbouring pixels in reading order): each
  // sample's L as Li would return it (bit for bit, except where the integrator says how it
  // differs). An integrator that traces its paths' rays together overrides it; the default
  // takes them one by one.
  struct CameraSample {
    Ray ray;
    SampledWavelengths* lambda;
    Sampler* sampler;
    Spectrum L{0.0f};
    int thread = 0;            // the render thread tracing it (< the render's thread count)
    float pixelEstimate = 0;   // a learning integrator's pixel, channel mean, from the iterations before (0: none)
  };
  virtual void LiPacket(CameraSample* samples, int n, const Scene& scene) const {
    for (int k = 0; k < n; ++k) samples[k].L = Li(samples[k].ray, scene, *samples[k].lambda, *samples[k].sampler);
  }
  // How many neighbouring pixels LiPacket takes at once: Scene::kPacket, or more for an
  // integrator that runs many paths side by side. Where it holds several rows, the renderer
  // hands it whole rows together (renderer.cpp).
  virtual int packetSize() const { return Scene::kPacket; }
  // --sampler sobol (core/sampler.h): how many of each camera path's draws, the pixel jitter
  // first, are Owen-scrambled Sobol' points over the pixel's samples; 0: independent draws.
  virtual int sobolSlots() const { return 0; }
  // Adds what the integrator knows to a checkpoint's info (photon counts, gather radius).
  virtual void addInfo(const Scene& scene, const RenderOptions& options, RenderInfo* info) const {}
  // An integrator that learns between iterations returns its hook; nullptr: one image, the mean
  // of every sample.
  virtual TrainingHook* training() { return nullptr; }
  ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) override;  // renderer.cpp
};

// What a light path is traced with: its wavelengths, its random stream, and the film it splats
// onto (through splat(), which turns a spectral value into RGB).
struct LightPathContext {
  int width, height;
  SampledWavelengths lambda;
  Rng rng;
  SplatBuffer* splats;
  // A contribution at film position `raster` (pixels), in the film's units (see LightPathIntegrator).
  void splat(const Vec2& raster, const Spectrum& value) {
    splats->add(raster, width, lambda.spectral ? spectralToRGB(value, lambda.lambda) : value);
  }
};

// Light-side integrators: paths start at the lights and splat onto the film. Iteration s traces
// W·H paths (one per pixel on average, so that `spp` buys the same number of paths as a camera-
// side integrator's); path i of it draws from the stream keyed by (seed, i, s). A path's
// contribution C to pixel j is an estimate of W·H times pixel j's share of the film's mean
// radiance (scene/camera.h), so after n iterations pixel j is Σ C / n. An iteration the budget
// cuts short is dropped whole: a part of one would brighten some regions only.
class LightPathIntegrator : public Integrator {
 public:
  virtual void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) {}
  virtual void traceLightPath(const Scene& scene, LightPathContext& path) const = 0;
  ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) override;  // render/light_loop.cpp
};

// Power heuristic with β = 2.
inline float powerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0 ? a / (a + b) : 0.0f;
}

// Next-event estimation at a non-delta surface point: one light chosen by power, one point on
// it, one shadow ray. Returns f·Li·|cosθ|/pdf. With `mis`, area-light samples are weighted by
// the power heuristic against BSDF sampling (Veach 1997); delta lights always get weight 1.
Spectrum estimateDirect(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, const SampledWavelengths& lambda,
                        Sampler& sampler, bool mis);

// Direct light at a non-specular point where the camera path ends, by both strategies, each
// weighted by the power heuristic (Veach 1997, §9.2.4; pbrt-v3's EstimateDirect): the light
// sample of estimateDirect(mis = true) and one BSDF sample that finds an area light or leaves
// for the sky. Light sampling alone leaves a narrow glossy lobe under a sky black with speckles
// (a sky sample rarely falls in the lobe); the visible points of the progressive photon maps,
// which no later vertex follows, need the BSDF half here.
Spectrum estimateDirectMIS(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, SampledWavelengths& lambda,
                           Sampler& sampler);

// What a camera path sees when its ray leaves the scene: the environment's radiance along it
// (0 without one). After a non-specular bounce it is weighted by the power heuristic against
// next-event estimation, which samples the same sky from the previous vertex with density
// pmf·p_env(ω), exactly as an emission hit is.
inline Spectrum escapedRadiance(const Scene& scene, const Vec3& direction, const SampledWavelengths& lambda,
                                bool specularBounce, float bsdfPdf) {
  const EnvironmentLight* env = scene.environment();
  if (!env) return Spectrum(0.0f);
  float pdf;
  Spectrum Le = env->radiance(direction, lambda, &pdf);
  if (specularBounce || isBlack(Le)) return Le;
  float lightPdf = scene.lightDistribution().pmf(size_t(scene.environmentIndex())) * pdf;
  return Le * powerHeuristic(bsdfPdf, lightPdf);
}

}  // namespace pl
