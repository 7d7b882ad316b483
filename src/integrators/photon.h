#pragma once
#include "integrators/integrator.h"
#include "photon/photon_tracer.h"

namespace pl {

// Jensen's two-pass photon mapping. Pass 1 (preprocess) traces the global and caustic maps.
// Pass 2, per eye ray: emission seen directly or through specular surfaces; specular surfaces
// by recursion; at the first diffuse or glossy hit x:
//   L = L_direct (shadow rays) + L_caustic (caustic map at x) + L_indirect,
// where L_indirect is either a final gather, N BSDF-sampled rays whose first non-specular hit y
// looks up the *whole* global map (light arriving at y by any path), or, with finalGather = 0,
// the global map at x itself without its direct and caustic photons (direct visualisation).
class PhotonIntegrator final : public Integrator {
 public:
  explicit PhotonIntegrator(const IntegratorOptions& options) : o_(options) {}
  void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) override;
  Spectrum Li(const Ray& ray, const Scene& scene, Rng& rng) const override;
  const char* name() const override { return "photon"; }
  std::vector<std::string> warnings() const override { return warnings_; }
  const PhotonMaps& maps() const { return maps_; }
  const DensityEstimation& density() const { return o_.density; }  // resolved by preprocess()

 private:
  Spectrum causticRadiance(const SurfaceHit& hit, const Vec3& wo) const;
  Spectrum finalGather(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, Rng& rng) const;
  IntegratorOptions o_;
  PhotonMaps maps_;
  std::vector<std::string> warnings_;
};

}  // namespace pl
