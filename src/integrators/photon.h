#pragma once
#include "render/integrator.h"
#include "photon/kernels.h"
#include "photon/photon_tracer.h"

namespace pl {

struct PhotonOptions {
  int maxDepth = 64;                 // maximum number of bounces
  uint64_t photons = 200000;         // emitted paths for the global map
  uint64_t causticPhotons = 200000;  // emitted paths for the caustic map
  DensityEstimation density;         // k / radius / max radius / kernel
  int finalGather = 32;              // gather rays per first diffuse hit; 0 = direct visualisation
  std::string aov;                   // "" (radiance), "photons" or "radius"
  bool spectral = false;             // photons carry wavelengths (with RenderOptions::spectral)
  bool targetView = true;       // --photon-target view: sky and sun photons aimed at the view
  bool aimAreaLights = false;   // --aim-area-lights on: area lights' photons too
  int width = 0, height = 0;         // the image, for the view's target
};

// Jensen's two-pass photon mapping. Pass 1 (preprocess) traces the global and caustic maps.
// Pass 2, per eye ray: emission seen directly or through specular surfaces; specular surfaces
// by recursion; at the first diffuse or glossy hit x:
//   L = L_direct (estimateDirectMIS) + L_caustic (caustic map at x) + L_indirect,
// where L_indirect is either a final gather, N BSDF-sampled rays whose first non-specular hit y
// looks up the *whole* global map (light arriving at y by any path), or, with finalGather = 0,
// the global map at x itself without its direct and caustic photons (direct visualisation).
class PhotonIntegrator final : public PixelIntegrator {
 public:
  explicit PhotonIntegrator(const PhotonOptions& options) : o_(options) {}
  void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) override;
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  const char* name() const override { return "photon"; }
  // Photon paths traced, and the mean gather radius (measured once, when the maps exist).
  void addInfo(const Scene& scene, const RenderOptions& options, RenderInfo* info) const override;
  std::vector<std::string> warnings() const override { return warnings_; }
  const PhotonMaps& maps() const { return maps_; }
  const DensityEstimation& density() const { return o_.density; }  // resolved by preprocess()
  // The estimate's defaults made explicit: without --radius and --max-radius, k-NN capped at 5%
  // of the scene's bounding radius; Jensen's disc a quarter of the radius thick.
  static DensityEstimation resolveDensity(const Scene& scene, DensityEstimation de);
  // The radius the global map's estimate actually used, summarised: its mean over the first
  // diffuse or glossy points a 32×32 grid of camera rays sees (render/visible_probe.h); the
  // fixed radius itself with --radius. 0 before preprocess() or without photons.
  double meanGatherRadius(const Scene& scene, int width, int height) const;

 private:
  Spectrum causticRadiance(const SurfaceHit& hit, const Vec3& wo, const SampledWavelengths& lambda) const;
  Spectrum finalGather(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, SampledWavelengths& lambda, Sampler& sampler) const;
  PhotonOptions o_;
  PhotonMaps maps_;
  mutable double gatherRadius_ = -1;  // meanGatherRadius(), once known
  std::vector<std::string> warnings_;
};

}  // namespace pl
