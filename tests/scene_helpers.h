// Small scenes with closed-form answers, built in code.
#pragma once
#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <vector>

#include "bsdfs/ggx_conductor.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/mirror.h"
#include "lights/point_light.h"
#include "image/image.h"
#include "scene/scene.h"

namespace pl::test {

inline void addQuad(Scene& scene, Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
  scene.addMesh({a, b, c, d}, {}, {}, {0, 1, 2, 0, 2, 3}, material);
}

inline uint32_t lambertian(Scene& scene, float rho) {
  return scene.addMaterial({"diffuse", std::make_unique<Lambertian>(ColorTexture(Spectrum(rho))), Spectrum(0), false});
}

inline Camera lookingDown(float height, float yfov = 0.8f) {
  Camera cam;
  cam.position = Vec3(0, height, 0);
  cam.forward = Vec3(0, -1, 0);
  cam.up = Vec3(0, 0, -1);
  cam.right = glm::cross(cam.forward, cam.up);
  cam.yfov = yfov;
  return cam;
}

// The open room of the glossy-floor tests (floor y = 0 and walls within [−1, 1]², 2 m high): a
// 0.6 m emitter facing down just under the ceiling, and a camera looking in from the open side.
inline void addRoomLight(Scene& scene, uint32_t light) {
  addQuad(scene, {-0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, 0.3f}, {-0.3f, 1.9f, 0.3f}, light);
}
inline Camera roomCamera() {
  Camera cam;
  cam.position = Vec3(0.4f, 1.0f, 2.2f);
  cam.forward = glm::normalize(Vec3(-0.3f, -0.45f, -1.0f));
  cam.right = glm::normalize(glm::cross(cam.forward, Vec3(0, 1, 0)));
  cam.up = glm::cross(cam.right, cam.forward);
  cam.yfov = 0.9f;
  return cam;
}

// Radiance L(ray) along each pixel's camera rays, averaged over the pixel (box filter) on a
// grid×grid midpoint rule.
inline ImageRGB expectedImage(const Scene& scene, int W, int H, const std::function<double(const Ray&)>& L, int grid = 6) {
  ImageRGB img(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double sum = 0;
      for (int a = 0; a < grid; ++a)
        for (int b = 0; b < grid; ++b) sum += L(scene.camera().generateRay(x + (a + 0.5f) / grid, y + (b + 0.5f) / grid, W, H));
      img.set(x, y, Spectrum(float(sum / (grid * grid))));
    }
  return img;
}

// The floor (y = 0) point seen through each pixel, closed form averaged over the pixel
// (box filter) on a grid×grid midpoint rule.
inline ImageRGB expectedFloorImage(const Scene& scene, int W, int H, const std::function<double(const Vec3&)>& L,
                                   int grid = 6) {
  ImageRGB img(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double sum = 0;
      for (int a = 0; a < grid; ++a)
        for (int b = 0; b < grid; ++b) {
          Ray r = scene.camera().generateRay(x + (a + 0.5f) / grid, y + (b + 0.5f) / grid, W, H);
          sum += L(r.o + (-r.o.y / r.d.y) * r.d);
        }
      img.set(x, y, Spectrum(float(sum / (grid * grid))));
    }
  return img;
}

// The mirror-caustic scene: diffuse floor (albedo rho) at y = 0, isotropic point light of
// intensity I at height h, a horizontal mirror of reflectance R at height H facing down,
// camera between light and mirror looking down. The floor receives
//   E = I cosθ/r² + R·I cosθ'/r'²   (the second from the mirror image of the light at 2H − h),
// plus light that bounced between floor and mirror, a fraction ~ρR of E (0.08% at ρ = 0.001).
// With glossyAlpha > 0 the floor is a GGX metal of F0 = rho and that roughness instead.
struct MirrorCaustic {
  float rho = 0.001f, h = 0.5f, H = 1.0f, I = 4.0f, R = 0.8f, glossyAlpha = 0.0f;
  std::unique_ptr<Scene> build(float cameraFov = 0.3f) const {
    auto scene = std::make_unique<Scene>();
    float s = 20.0f;
    const uint32_t floor = glossyAlpha > 0 ? scene->addMaterial({"metal", std::make_unique<GGXConductor>(ColorTexture(Spectrum(rho)), glossyAlpha),
                                                                 Spectrum(0), false})
                                           : lambertian(*scene, rho);
    addQuad(*scene, {-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, floor);
    uint32_t mirror = scene->addMaterial({"mirror", std::make_unique<Mirror>(ColorTexture(Spectrum(R))), Spectrum(0), false});
    addQuad(*scene, {-s, H, -s}, {s, H, -s}, {s, H, s}, {-s, H, s}, mirror);
    scene->addLight(std::make_unique<PointLight>(Vec3(0, h, 0), Spectrum(I)));
    scene->setCamera(lookingDown(0.9f * H, cameraFov));
    scene->commit();
    return scene;
  }
  double radiance(const Vec3& x, bool withCaustic = true) const {
    auto term = [&](float height, float scale) {
      double r2 = double(height) * height + x.x * x.x + x.z * x.z;
      return scale * I * (height / std::sqrt(r2)) / r2;
    };
    return rho / kPi * (term(h, 1.0f) + (withCaustic ? term(2 * H - h, R) : 0.0));
  }
};

inline double meanOf(const ImageRGB& img) {
  double s = 0;
  for (float v : img.data) s += v;
  return s / img.data.size();
}

// Per-pixel agreement of two renders (seeds 1 and 2) with their closed form e (grey scenes: the
// green channel). Noise differs from pixel to pixel (a spot's cone edge varies within a pixel
// far more than its centre), so each pixel's error is measured against its own noise level:
// σ² at a pixel is estimated from the two seeds' differences d = x₁ − x₂ over its 3×3
// neighbourhood, σ̂² = mean(d²)/2, and t = (x₁ − e)/σ̂ then follows roughly Student's t with 9
// degrees of freedom (99th percentile of |t|: 3.25). A wrong level shows in the median ratio;
// salt noise, or a region off by more than its noise, in the 99th percentile of |t|.
struct PixelAgreement {
  double medianRatio;  // median of x₁/e over pixels with e above a tenth of the mean
  double meanRatio;    // mean(x₁ + x₂)/(2 mean(e))
  double p99t;         // 99th percentile of |t| over all pixels
};
// One seed's variance at pixel (x, y), green channel, from two seeds' differences d = a − b over
// its 3×3 neighbourhood (clamped at the edges): mean(d²)/2.
inline double neighbourhoodVariance(const ImageRGB& a, const ImageRGB& b, int x, int y) {
  const int W = a.width, H = a.height;
  double d2 = 0;
  int n = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int u = std::clamp(x + dx, 0, W - 1), v = std::clamp(y + dy, 0, H - 1);
      const double d = double(a.at(u, v).g) - double(b.at(u, v).g);
      d2 += d * d, ++n;
    }
  return d2 / n / 2;
}

inline PixelAgreement pixelAgreement(const ImageRGB& a, const ImageRGB& b, const ImageRGB& e) {
  const int W = e.width, H = e.height;
  const double mean = meanOf(e);
  auto g = [](const ImageRGB& img, int x, int y) { return double(img.at(x, y).g); };
  std::vector<double> ratio, t;
  double sum = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      // A floor of 10⁻⁴ of the mean level: exact estimators (a directional light's shadow rays) have no noise.
      double sigma = std::max(std::sqrt(neighbourhoodVariance(a, b, x, y)), 1e-4 * mean);
      t.push_back(std::abs(g(a, x, y) - g(e, x, y)) / sigma);
      if (g(e, x, y) > 0.1 * mean) ratio.push_back(g(a, x, y) / g(e, x, y));
      sum += g(a, x, y) + g(b, x, y);
    }
  std::sort(ratio.begin(), ratio.end());
  std::sort(t.begin(), t.end());
  return {ratio[ratio.size() / 2], sum / (2 * mean * W * H), t[size_t(0.99 * (t.size() - 1))]};
}

// The per-pixel acceptance of the light-transport tests: two seeds of an estimator against an
// expected image, median and mean ratio within 1 ± margin, and the 99th percentile of |t| below
// 4.5 (3.25 for t₉; the margin covers the neighbourhood's uneven noise).
inline void checkAgreesPerPixel(const std::function<ImageRGB(uint64_t)>& renderSeed, const ImageRGB& expected,
                                double margin = 0.02) {
  PixelAgreement pa = pixelAgreement(renderSeed(1), renderSeed(2), expected);
  INFO("median ratio " << pa.medianRatio << ", mean ratio " << pa.meanRatio << ", p99 |t| " << pa.p99t);
  CHECK(pa.medianRatio == Approx(1.0).margin(margin));
  CHECK(pa.meanRatio == Approx(1.0).margin(margin));
  CHECK(pa.p99t < 4.5);
}

// The mirror caustic rendered by `render(scene, seed)` at 24×24 pixels with seeds 1 and 2,
// against its closed form per pixel. Only the light side reaches the mirror-image term (9% of the
// direct one under the light); a pixel's splats or merges are a Poisson count of ~12 at 512
// paths per pixel, so its noise is ~30% and the mean over 2 × 576 pixels is good to ~1%.
// Accepted: the mean within 1 ± 0.03 of the closed form (the image without the caustic term is
// 5% or more away), the median ratio within 1 ± 0.05 (a Poisson count of ~12 has its median ~3%
// below its mean), the 99th percentile of the per-pixel |t| below 4.5 (pixelAgreement).
template <typename RenderFn>
void checkMirrorCaustic(RenderFn&& render) {
  MirrorCaustic mc;
  auto scene = mc.build();
  const int W = 24;
  ImageRGB withCaustic = expectedFloorImage(*scene, W, W, [&](const Vec3& x) { return mc.radiance(x); });
  ImageRGB withoutCaustic = expectedFloorImage(*scene, W, W, [&](const Vec3& x) { return mc.radiance(x, false); });
  REQUIRE(meanOf(withCaustic) / meanOf(withoutCaustic) > 1.05);
  ImageRGB a = render(*scene, W, uint64_t(1)), b = render(*scene, W, uint64_t(2));
  PixelAgreement pa = pixelAgreement(a, b, withCaustic);
  INFO("median ratio " << pa.medianRatio << ", mean ratio " << pa.meanRatio << ", p99 |t| " << pa.p99t);
  CHECK(pa.meanRatio == Approx(1.0).margin(0.03));
  CHECK(pa.medianRatio == Approx(1.0).margin(0.05));
  CHECK(pa.p99t < 4.5);
}

// The closed furnace (scenes/furnace.gltf: Le = 1, ρ = 0.5, every pixel's expectation 2), two
// seeds' renders a and b: the mean within 1%, then no structure beyond noise: the pixels' spread
// around 2 over the seeds' noise (variance mean(d²)/2 from their differences d) within
// [0.7, 1.4] (a wrong importance or a biased weight would brighten some pixels).
inline void checkFurnace(const ImageRGB& a, const ImageRGB& b) {
  double mean = 0;
  for (size_t i = 0; i < a.data.size(); ++i) mean += (a.data[i] + b.data[i]) / 2.0;
  CHECK(mean / a.data.size() == Approx(2.0).epsilon(0.01));
  double spread = 0, noise = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    spread += ((a.data[i] - 2.0) * (a.data[i] - 2.0) + (b.data[i] - 2.0) * (b.data[i] - 2.0)) / 2;
    noise += (a.data[i] - b.data[i]) * (a.data[i] - b.data[i]) / 2;
  }
  INFO("spread " << spread / a.data.size() << ", noise " << noise / a.data.size());
  CHECK(spread / noise > 0.7);
  CHECK(spread / noise < 1.4);
}

// Two estimators a and b of one image, each rendered with two seeds, compared over B×B regions:
// z = (mean_a − mean_b)/σ. σ² starts from the seeds' per-pixel differences summed over the
// region, which is the variance of the region's mean when its pixels' errors are independent.
// Density estimation makes neighbours share photons (or merged light vertices), and then the
// region's mean varies more than its pixels' sum says: the seeds' region means, which differ by
// that true variance, give the factor F = Σ (m₁ − m₂)²/4 / Σ (per-pixel estimate) over all
// regions and both estimators (hundreds of degrees of freedom), and σ² is scaled by max(1, F).
// F comes from each estimator's own two seeds, never from a against b, so a bias still shows.
struct RegionAgreement {
  double worst = 0, meanZ2 = 0;
  double correlation = 1;  // max(1, F)
};
inline RegionAgreement regions(const ImageRGB& a1, const ImageRGB& a2, const ImageRGB& b1, const ImageRGB& b2, int B,
                        double floor = 0) {
  const int W = a1.width, H = a1.height;
  const double k = double(B) * B;
  struct Region {
    double difference, pixelVariance;  // mean_a − mean_b; the per-pixel estimate of its variance
  };
  std::vector<Region> found;
  double seedVariance = 0, pixelVariance = 0;  // Σ over regions, both estimators
  for (int by = 0; by < H / B; ++by)
    for (int bx = 0; bx < W / B; ++bx)
      for (int c = 0; c < 3; ++c) {
        double a1s = 0, a2s = 0, b1s = 0, b2s = 0, va = 0, vb = 0;
        for (int y = by * B; y < (by + 1) * B; ++y)
          for (int x = bx * B; x < (bx + 1) * B; ++x) {
            size_t i = (size_t(y) * W + x) * 3 + c;
            a1s += a1.data[i], a2s += a2.data[i], b1s += b1.data[i], b2s += b2.data[i];
            double da = a1.data[i] - a2.data[i], db = b1.data[i] - b2.data[i];
            va += da * da / 2, vb += db * db / 2;
          }
        const double pixelEstimate = (va + vb) / (k * k) / 2;  // Var(mean_a) + Var(mean_b), two seeds each
        if (std::sqrt(pixelEstimate) <= floor) continue;  // nothing there (black regions) in either
        const double da = (a1s - a2s) / k, db = (b1s - b2s) / k;
        seedVariance += (da * da + db * db) / 4;
        pixelVariance += pixelEstimate;
        found.push_back({((a1s + a2s) - (b1s + b2s)) / (2 * k), pixelEstimate});
      }
  RegionAgreement r;
  r.correlation = pixelVariance > 0 ? std::max(1.0, seedVariance / pixelVariance) : 1.0;
  for (const Region& g : found) {
    const double z = g.difference / std::sqrt(g.pixelVariance * r.correlation);
    r.worst = std::max(r.worst, std::abs(z));
    r.meanZ2 += z * z;
  }
  r.meanZ2 /= std::max<size_t>(1, found.size());
  return r;
}

}  // namespace pl::test
