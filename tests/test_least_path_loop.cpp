// The least path tracer that `photonlab bench` measures the path tracer against
// (bench/least_path_loop.h). Its rate means something only if it computes the same image with
// the same work: so it must agree with the path tracer region by region (two independent
// implementations of one estimator), trace the same rays per sample, and refuse the scenes it
// cannot render rather than render them wrongly.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include "bench/least_path_loop.h"
#include "integrator_helpers.h"
#include "lanes_helpers.h"
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

TEST_CASE("the least path loop in 16 SIMD lanes computes the one-path loop's image pixel by pixel, the same whatever the thread count") {
  // Both loops trace each path with the same random numbers (Rng::keyed(seed, pixel, sample),
  // drawn in the same order) and Embree's 16-ray packets return the one-ray queries' hits. What
  // may differ is rounding: the lanes take 1/√r² once where the scalar loop divides, and group
  // the NEE product differently. That moves a pixel by a few ulps; rarely it flips a comparison
  // (a roulette draw next to q, a cosine next to 0), which changes one sample of a pixel. A wrong
  // term (a weight, a density, a draw out of order) would change nearly every pixel instead.
  // 48 × 40 pixels (rows of 48 paths: three packets, so compaction moves paths across packets),
  // 16 spp, seeds 1 and 5.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  const int W = 48, H = 40, spp = 16;
  // Each copy of the kernel (core/lanes_copies.h): AVX-512 where the CPU has it, and baseline.
  for (const char* isa : lanesCopies())
  for (uint64_t seed : {1, 5}) {
    INFO("the " << isa << " copy");
    LanesCopy copy(isa);
    const LeastPathResult one = leastPathLoop(*scene, W, H, spp, 64, 2, seed);
    const LeastPathResult lanes = leastPathLoopSimd(*scene, W, H, spp, 64, 2, seed);
    size_t differing = 0;  // pixel-channels more than 10⁻⁴ apart (relative)
    double sumOne = 0, sumLanes = 0;
    for (size_t i = 0; i < one.image.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const float a = one.image[i][c], b = lanes.image[i][c];
        differing += std::abs(a - b) > 1e-4f * std::max(std::abs(a), 1e-3f);
        sumOne += a, sumLanes += b;
      }
    // Seen: 0.1% of pixel-channels (13 of 12 288 at 64², 16 spp), each from one flipped sample.
    INFO("seed " << seed << ": " << differing << " of " << 3 * one.image.size() << " pixel-channels differ");
    CHECK(differing <= one.image.size() * 3 / 100);
    CHECK(sumLanes == Approx(sumOne).epsilon(1e-3));
    // The same paths: the same closest-hit rays, and shadow rays but for a flipped few.
    CHECK(lanes.closestRays == Approx(double(one.closestRays)).epsilon(1e-3));
    CHECK(lanes.shadowRays == Approx(double(one.shadowRays)).epsilon(1e-3));
    // Rows are independent work items: one thread gives the same bits as two.
    const LeastPathResult single = leastPathLoopSimd(*scene, W, H, spp, 64, 1, seed);
    CHECK(std::memcmp(single.image.data(), lanes.image.data(), lanes.image.size() * sizeof(Vec3)) == 0);
  }
}

TEST_CASE("the least path loop refuses what it does not render: mirrors, glass, point lights, a sky") {
  for (const char* name : {"cornell-spheres.gltf", "smallvcm-point.gltf", "sky.gltf"}) {
    auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name);
    INFO(name << ": " << leastPathLoopUnsupported(*scene));
    CHECK_FALSE(leastPathLoopUnsupported(*scene).empty());
    CHECK_THROWS_AS(leastPathLoop(*scene, 8, 8, 1, 64, 1, 1), Error);
    CHECK_THROWS_AS(leastPathLoopSimd(*scene, 8, 8, 1, 64, 1, 1), Error);
  }
}
