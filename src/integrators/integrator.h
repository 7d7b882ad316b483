// The integrator interface: radiance arriving along a camera ray. Each integrator is one file;
// makeIntegrator() is the only place that knows them all.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/budget.h"
#include "core/rng.h"
#include "photon/kernels.h"
#include "scene/scene.h"

namespace pl {

struct IntegratorOptions {
  int maxDepth = 64;  // maximum number of bounces (path segments after the camera ray)
  // Photon mapping (--integrator photon).
  uint64_t photons = 200000;         // emitted paths for the global map
  uint64_t causticPhotons = 200000;  // emitted paths for the caustic map
  DensityEstimation density;         // k / radius / max radius / kernel
  int finalGather = 32;              // gather rays per first diffuse hit; 0 = direct visualisation
  std::string aov;                   // "" (radiance), "photons" or "radius"
  bool spectral = false;             // photons carry wavelengths (with RenderOptions::spectral)
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Work done once before the first sample (photon tracing). Deterministic for a seed. It polls
  // the render's budget: when that expires the render stops, whatever preprocess() has left.
  virtual void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) {}
  virtual Spectrum Li(const Ray& ray, const Scene& scene, Rng& rng) const = 0;
  virtual const char* name() const = 0;
  // Things the user should know (e.g. "no photons were stored"), printed by the CLI.
  virtual std::vector<std::string> warnings() const { return {}; }
};

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& options);
// Every integrator's name: the per-sample ones above and the progressive ones
// (progressive/progressive.h); integratorList() joins them for messages.
std::vector<std::string> integratorNames();
std::string integratorList();

// Next-event estimation at a non-delta surface point: one light chosen by power, one point on
// it, one shadow ray. Returns f·Li·|cosθ|/pdf. With `mis`, area-light samples are weighted by
// the power heuristic against BSDF sampling (Veach 1997); delta lights always get weight 1.
Spectrum estimateDirect(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, Rng& rng, bool mis);

// Power heuristic with β = 2.
inline float powerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0 ? a / (a + b) : 0.0f;
}

}  // namespace pl
