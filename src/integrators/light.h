#pragma once
#include "render/integrator.h"

namespace pl {

// Light tracing, or particle tracing (Arvo & Kirk 1990; Veach 1997 §10.2; "forward ray tracing"
// in the course notes): paths start at the lights with flux Φ/pmf and scatter as photons do, and
// every non-specular vertex is connected to the camera and splatted onto the film:
//   C = β f(x, ωl → ωc) |cos θx| We / pdf_cam,   pdf_cam = d²/cos θcam,   We = 1/(A cos⁴θcam),
// with β the flux the path carries into x and ωl, ωc the directions towards the light side and
// towards the camera (the BSDF in importance mode, with the shading-normal correction). An
// area light's emission point is connected too, so that the light looks as the path tracer sees
// it; a point, spot or directional light cannot be seen (no camera ray hits it) and is not.
// Caustics seen directly (L S+ D E) come for free: what the path tracer finds only by chance
// from a small light is one deterministic connection here. What it cannot render is what the
// camera sees through a mirror or glass (L ... S E): the camera is a pinhole, no connection
// reaches it through a specular surface; those pixels stay black.
class LightTracer final : public LightPathIntegrator {
 public:
  explicit LightTracer(int maxDepth) : maxDepth_(maxDepth) {}
  void traceLightPath(const Scene& scene, LightPathContext& path) const override;
  const char* name() const override { return "light"; }

 private:
  // Splats the light arriving at `hit` from wo (world) with flux beta, reflected to the camera.
  void connectToCamera(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, const Spectrum& beta,
                       LightPathContext& path) const;
  int maxDepth_;
};

}  // namespace pl
