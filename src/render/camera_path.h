// The start of every camera path, written once: the random stream keyed by (seed, pixel,
// sample or pass), the camera ray through a jittered point of the pixel, and the path's
// wavelengths (spectral mode). Both loops that start camera paths use it: the per-pixel loop
// (render/renderer.cpp) and the progressive eye passes (integrators/progressive.h).
#pragma once
#include "core/rng.h"
#include "core/sampler.h"
#include "render/render_options.h"
#include "scene/scene.h"
#include "spectral/spectral.h"

namespace pl {

struct CameraPath {
  Rng rng;
  Ray ray;
  SampledWavelengths lambda;
};

inline CameraPath beginCameraPath(const Scene& scene, const RenderOptions& image, int x, int y, uint64_t sample) {
  const uint64_t pixel = uint64_t(y) * uint64_t(image.width) + uint64_t(x);
  CameraPath c{Rng::keyed(image.seed, pixel, sample), Ray{}, SampledWavelengths()};
  const float jx = c.rng.uniform();  // two statements: the order of the draws is fixed, x first
  const float jy = c.rng.uniform();
  c.ray = scene.cameraRay(x + jx, y + jy, image.width, image.height);
  if (image.spectral) c.lambda = SampledWavelengths::sample(c.rng.uniform());
  return c;
}

// --sampler sobol: the pixel jitter is the sampler's first draw, so the ray beginCameraPath made
// from the stream's jitter is made again from it (one generateRay per path, against keeping a
// second start for the Sobol' case). With independent draws, nothing changes.
inline void jitterFromSampler(const Scene& scene, int x, int y, int width, int height, Sampler& sampler, Ray* ray) {
  if (!sampler.sobol()) return;
  const Vec2 jitter = sampler.get2D();
  *ray = scene.cameraRay(float(x) + jitter.x, float(y) + jitter.y, width, height);
}

}  // namespace pl
