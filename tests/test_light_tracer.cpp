// The light tracer and what it stands on: the camera as an emitter of importance, the lights'
// emission densities, the splat film. Expected values come from closed forms (the film's area,
// the mirror image of a point light, the furnace's geometric series) or from the path tracer,
// an independent estimator of the same integral.
#include <catch2/catch.hpp>

#include "core/sampling.h"
#include "integrator_helpers.h"
#include "lights/area_light.h"
#include "lights/directional_light.h"
#include "lights/spot_light.h"
#include "lights/warn_spotlight.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

ImageRGB renderLight(const Scene& scene, int W, int spp, uint64_t seed = 1, int threads = 0) {
  RenderOptions ro;
  ro.width = ro.height = W;
  ro.spp = spp;
  ro.seed = seed;
  ro.threads = threads;
  return render(scene, *makeIntegrator("light", ro), ro, nullptr);
}

}  // namespace

TEST_CASE("light tracing: the mirror caustic of a point light - E = I/h² + R·I/(2H − h)² per pixel - which the path tracer cannot render") {
  // scene_helpers' MirrorCaustic: a point light between a diffuse floor and a mirror; a path
  // tracer never finds the mirror-image term (no ray hits a point light), the light tracer's
  // paths that bounce off the mirror splat it. 512 paths per pixel; only ~2% of them land in view.
  checkMirrorCaustic([](const Scene& scene, int W, uint64_t seed) { return renderLight(scene, W, 512, seed); });
}

TEST_CASE("light tracing: the closed furnace converges to L = Le/(1 − ρ) = 2") {
  // scenes/furnace.gltf: emissive diffuse walls, Le = 1, ρ = 0.5, the camera inside. Every
  // pixel's expectation is 2 (its emission seen directly through the light-point connection
  // plus the geometric series of bounces). 16×16 pixels, 256 paths per pixel, seeds 1 and 2:
  // the mean within 1%, as the path tracer's furnace test asks; and no structure beyond noise:
  // the pixels' spread around 2 is the seeds' noise (variance mean(d²)/2 from their
  // differences d), a ratio within [0.7, 1.4] over 2 × 768 values (a wrong importance We
  // would brighten the film's corners).
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/furnace.gltf");
  ImageRGB a = renderLight(*scene, 16, 256, 1), b = renderLight(*scene, 16, 256, 2);
  checkFurnace(a, b);
}

TEST_CASE("light tracing agrees with the path tracer region by region on the Cornell box") {
  // Two independent estimators of the same image: 32×32 pixels cut into 4×4 regions of 8×8.
  // Each is rendered with seeds 1 and 2; a region's noise comes from the seeds' per-pixel
  // differences d (pixels are independent estimates): var(region mean over both seeds) =
  // Σ d²/2 / 64² / 2. z = (light − path)/√(var_light + var_path) should be standard normal:
  // every |z| < 4 over the 16 regions (a false alarm ~10⁻³), mean z² < 3, and the image means
  // within 1.5%.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  const int W = 32, B = 8;
  RenderOptions ro;
  ro.width = ro.height = W;
  ro.spp = 256;
  auto renderPath = [&](uint64_t seed) {
    RenderOptions o = ro;
    o.seed = seed;
    return render(*scene, *makeIntegrator("path", o), o, nullptr);
  };
  ImageRGB l1 = renderLight(*scene, W, 256, 1), l2 = renderLight(*scene, W, 256, 2);
  ImageRGB p1 = renderPath(1), p2 = renderPath(2);
  RegionAgreement r = regions(l1, l2, p1, p2, B);
  INFO("mean z² " << r.meanZ2 << ", worst |z| " << r.worst);
  CHECK(r.worst < 4.0);
  CHECK(r.meanZ2 < 3.0);
  CHECK((meanOf(l1) + meanOf(l2)) / (meanOf(p1) + meanOf(p2)) == Approx(1.0).epsilon(0.015));
}

TEST_CASE("light tracing is deterministic: the same image bit for bit with 1 or 2 threads - and spectral") {
  // Splats go to per-chunk buffers added in chunk order (render/film.h): the sums do not
  // depend on which thread traced what.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-spheres.gltf");
  ImageRGB one = renderLight(*scene, 48, 4, 9, 1), two = renderLight(*scene, 48, 4, 9, 2);
  CHECK(one.data == two.data);
  CHECK(renderLight(*scene, 48, 4, 10, 2).data != two.data);  // and the seed matters
  RenderOptions ro;
  ro.width = ro.height = 24;
  ro.spp = 2;
  ro.spectral = true;
  ro.threads = 1;
  ImageRGB s1 = render(*scene, *makeIntegrator("light", ro), ro, nullptr);
  ro.threads = 2;
  CHECK(render(*scene, *makeIntegrator("light", ro), ro, nullptr).data == s1.data);
}
