// The least path tracer that `photonlab bench` measures the path tracer against
// (bench/least_path_loop.h). Its rate means something only if it computes the same image with
// the same work: so it must agree with the path tracer region by region (two independent
// implementations of one estimator), trace the same rays per sample, and refuse the scenes it
// cannot render rather than render them wrongly.
#include <catch2/catch.hpp>

#include "bench/least_path_loop.h"
#include "integrator_helpers.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

ImageRGB imageOf(const LeastPathResult& r, int W) {
  ImageRGB image(W, W);
  for (int y = 0; y < W; ++y)
    for (int x = 0; x < W; ++x) image.set(x, y, r.image[size_t(y) * W + x]);
  return image;
}

}  // namespace

TEST_CASE("the least path loop agrees with the path tracer region by region on the Cornell box, with the same rays per sample") {
  // 32×32 pixels in 4×4 regions of 8×8, 256 samples per pixel, seeds 1 and 2 on each side; a
  // region's noise from the seeds' per-pixel differences (scene_helpers' regions): every
  // |z| < 4 over the 48 region-channels (a false alarm ~3·10⁻³), mean z² < 3.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  INFO(leastPathLoopUnsupported(*scene));
  REQUIRE(leastPathLoopUnsupported(*scene).empty());
  const int W = 32, spp = 256;
  RenderOptions ro;
  ro.width = ro.height = W;
  ro.spp = spp;
  auto renderPath = [&](uint64_t seed) {
    RenderOptions o = ro;
    o.seed = seed;
    return render(*scene, *makeIntegrator("path", o), o, nullptr);
  };
  const uint64_t rays0 = Scene::raysTraced(), shadow0 = Scene::shadowRaysTraced();
  ImageRGB p1 = renderPath(1), p2 = renderPath(2);
  const double samples = 2.0 * W * W * spp;
  const double pathClosest = double(Scene::raysTraced() - rays0 - (Scene::shadowRaysTraced() - shadow0)) / samples;
  const double pathShadow = double(Scene::shadowRaysTraced() - shadow0) / samples;
  LeastPathResult l1 = leastPathLoop(*scene, W, W, spp, 64, 2, 1), l2 = leastPathLoop(*scene, W, W, spp, 64, 2, 2);
  RegionAgreement r = regions(imageOf(l1, W), imageOf(l2, W), p1, p2, 8);
  INFO("mean z² " << r.meanZ2 << ", worst |z| " << r.worst);
  CHECK(r.worst < 4.0);
  CHECK(r.meanZ2 < 3.0);
  // Rays per sample: a closest-hit ray per bounce and a shadow ray per diffuse vertex whose
  // light sample faces it. Their counts are sums of ~10⁶ path lengths (spread ~2 around a
  // mean of ~3.3): the two means' difference has σ ≈ 2/√(2·10⁵·2) ~ 0.3%; within 1.5%.
  const double leastClosest = double(l1.closestRays + l2.closestRays) / samples;
  const double leastShadow = double(l1.shadowRays + l2.shadowRays) / samples;
  INFO("closest-hit rays per sample " << pathClosest << " / " << leastClosest << ", shadow " << pathShadow << " / " << leastShadow);
  CHECK(leastClosest == Approx(pathClosest).epsilon(0.015));
  CHECK(leastShadow == Approx(pathShadow).epsilon(0.015));
}

TEST_CASE("the least path loop refuses what it does not render: mirrors, glass, point lights, a sky") {
  for (const char* name : {"cornell-spheres.gltf", "smallvcm-point.gltf", "sky.gltf"}) {
    auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name);
    INFO(name << ": " << leastPathLoopUnsupported(*scene));
    CHECK_FALSE(leastPathLoopUnsupported(*scene).empty());
    CHECK_THROWS_AS(leastPathLoop(*scene, 8, 8, 1, 64, 1, 1), Error);
  }
}
