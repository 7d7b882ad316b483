// Whole renders at small resolution against closed forms, agreement between integrators, and
// determinism across thread counts.
#include <catch2/catch.hpp>

#include <atomic>
#include <stdexcept>
#include <thread>

#include "bsdfs/dielectric.h"
#include "core/parallel.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/ggx_conductor.h"
#include "lights/environment_light.h"
#include "lights/point_light.h"
#include "lights/warn_spotlight.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"

using namespace pl;
using Catch::Matchers::Contains;

namespace {

const float kRho = 0.6f;

// A large diffuse floor at y = 0, seen from (0, H, 0) looking straight down.
std::unique_ptr<Scene> floorScene(float cameraHeight, float yfov) {
  auto scene = std::make_unique<Scene>();
  float s = 50.0f;
  test::addQuad(*scene, {-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, test::lambertian(*scene, kRho));
  scene->setCamera(test::lookingDown(cameraHeight, yfov));
  return scene;
}

template <typename Radiance>
ImageRGB expectedImage(const Scene& scene, int W, int H, Radiance radianceAt) {
  return test::expectedFloorImage(scene, W, H, [&](const Vec3& p) { return double(radianceAt(p)); });
}

double maxRelativeError(const ImageRGB& a, const ImageRGB& b) {
  double worst = 0;
  for (size_t i = 0; i < a.data.size(); ++i) worst = std::max(worst, std::abs(a.data[i] / b.data[i] - 1.0));
  return worst;
}

// Pixel jitter estimates each pixel's box-filter average by Monte Carlo: across a steep
// 1/r³ falloff that is noisy per pixel, so check the image-wide mean tightly and each pixel
// loosely.
void checkAgainstClosedForm(const ImageRGB& img, const ImageRGB& expected, double meanTolerance, double pixelTolerance) {
  double sum = 0, sumExpected = 0;
  for (size_t i = 0; i < img.data.size(); ++i) sum += img.data[i], sumExpected += expected.data[i];
  CHECK(sum / sumExpected == Approx(1.0).epsilon(meanTolerance));
  CHECK(maxRelativeError(img, expected) < pixelTolerance);
}

double mean(const ImageRGB& img) {
  double s = 0;
  for (float v : img.data) s += v;
  return s / img.data.size();
}

ImageRGB renderWith(const Scene& scene, const std::string& integrator, int W, int spp, int threads = 0, int maxDepth = 64,
                    const std::string& sampler = "independent", uint64_t seed = 1) {
  RenderOptions o;
  o.width = o.height = W;
  o.spp = spp;
  o.threads = threads;
  o.seed = seed;
  auto in = test::makeWith(integrator, {{"max_depth", maxDepth}}, o, {{"sampler", sampler}});
  return render(scene, *in, o, nullptr);
}

}  // namespace

TEST_CASE("point light over a diffuse floor: L = ρ/π · I cosθ / r² (E = Φ cosθ / 4πr²)") {
  const float h = 1.0f, I = 5.0f;
  auto scene = floorScene(2.5f, 0.8f);
  scene->addLight(std::make_unique<PointLight>(Vec3(0, h, 0), Spectrum(I)));
  scene->commit();
  ImageRGB expected = expectedImage(*scene, 16, 16, [&](const Vec3& p) {
    float r2 = h * h + p.x * p.x + p.z * p.z, cosTheta = h / std::sqrt(r2);
    return kRho / kPi * I * cosTheta / r2;
  });
  // Directly below the light the classic formula: L = ρ/π · I/h².
  Ray centre = scene->camera().generateRay(8, 8, 16, 16);
  CHECK(centre.d.y == Approx(-1.0f));
  for (const char* integrator : {"direct", "whitted", "path"}) {
    INFO(integrator);
    checkAgainstClosedForm(renderWith(*scene, integrator, 16, 64), expected, 0.002, 0.03);
  }
}

TEST_CASE("Warn spotlight over a floor: L = ρ/π · c cosˢθ · cosθ / r²") {
  const float h = 1.2f, s = 6.0f;
  auto scene = floorScene(2.5f, 0.9f);
  Spectrum c = WarnSpotlight::cForPower(Spectrum(20.0f), s);
  scene->addLight(std::make_unique<WarnSpotlight>(Vec3(0, h, 0), Vec3(0, -1, 0), c, s));
  scene->commit();
  ImageRGB expected = expectedImage(*scene, 16, 16, [&](const Vec3& p) {
    float r2 = h * h + p.x * p.x + p.z * p.z, cosTheta = h / std::sqrt(r2);
    return kRho / kPi * c.g * std::pow(cosTheta, s) * cosTheta / r2;
  });
  checkAgainstClosedForm(renderWith(*scene, "path", 16, 64), expected, 0.003, 0.06);
}

TEST_CASE("small area light over a floor: Lambert's polygon formula - direct and path agree") {
  // Square light (side 0.2 m) at height 0.5 m facing down, radiance 10 W/(m²·sr).
  const float h = 0.5f, a = 0.1f, Le = 10.0f;
  auto scene = floorScene(2.0f, 0.6f);
  uint32_t light = scene->addMaterial({"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0))), Spectrum(Le), false});
  Vec3 v[4] = {{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}};  // counter-clockwise seen from below
  scene->addMesh({v[0], v[1], v[2], v[3]}, {}, {}, {0, 1, 2, 0, 2, 3}, light);
  scene->commit();
  REQUIRE(scene->lights().size() == 2);
  CHECK(scene->totalPower().g == Approx(kPi * Le * 4 * a * a));
  ImageRGB expected = expectedImage(*scene, 12, 12, [&](const Vec3& x) {
    double E = 0;
    for (int i = 0; i < 4; ++i) {
      Vec3 ui = glm::normalize(v[i] - x), uj = glm::normalize(v[(i + 1) % 4] - x);
      E += std::acos(std::clamp(glm::dot(ui, uj), -1.0f, 1.0f)) * glm::normalize(glm::cross(ui, uj)).y;
    }
    return float(kRho / kPi * Le * std::abs(E) / 2);
  });
  // The light itself hides the floor right below it from the camera: skip those pixels.
  auto compare = [&](const ImageRGB& img) {
    double worst = 0, sumImg = 0, sumExp = 0;
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 12; ++x) {
        Ray r = scene->camera().generateRay(x + 0.5f, y + 0.5f, 12, 12);
        Vec3 p = r.o + (-r.o.y / r.d.y) * r.d;
        if (std::abs(p.x) < 0.35f && std::abs(p.z) < 0.35f) continue;
        worst = std::max(worst, double(std::abs(img.at(x, y).g / expected.at(x, y).g - 1)));
        sumImg += img.at(x, y).g;
        sumExp += expected.at(x, y).g;
      }
    CHECK(sumImg / sumExp == Approx(1.0).epsilon(0.01));
    CHECK(worst < 0.06);
  };
  compare(renderWith(*scene, "direct", 12, 256));
  compare(renderWith(*scene, "path", 12, 256));
}

TEST_CASE("estimateDirectMIS: light and BSDF samples under the power heuristic - light sampling's mean, and on a narrow lobe under a sky a fraction of its noise") {
  // A GGX conductor floor (F0 = 1) alone under a constant sky L = 1: every direction above it sees
  // the sky, so the direct light is L ∫ f cos dω, which both estimateDirect (light samples
  // alone) and estimateDirectMIS are unbiased for. Their means over n = 200,000 samples must
  // agree within 5 standard errors of the difference. On a narrow lobe (α = 0.02), a uniform sky
  // sample falls inside it once in thousands of draws; the BSDF sample finds the sky every time:
  // the MIS estimate's standard deviation must be below a tenth of light sampling's. A light
  // sample weighted twice, or a BSDF half weighted 1, moves the mean by tens of per cent, far
  // outside the bound.
  for (float alpha : {0.3f, 0.02f}) {
    INFO("alpha " << alpha);
    Scene scene;
    uint32_t metal = scene.addMaterial({"metal", std::make_unique<GGXConductor>(ColorTexture(Spectrum(1.0f)), alpha), Spectrum(0.0f), false});
    test::addQuad(scene, {-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, metal);
    scene.addLight(EnvironmentLight::constant(Spectrum(1.0f)));
    scene.commit();
    SurfaceHit hit;
    const Vec3 d = glm::normalize(Vec3(0.6f, -1.0f, 0.2f));
    REQUIRE(scene.intersect(Ray{Vec3(0, 1, 0), d}, &hit));
    const Vec3 wo = hit.shading.toLocal(-d);
    const int n = 200000;
    double sum[2] = {0, 0}, sum2[2] = {0, 0};
    Rng rng(11);
    Sampler sampler(rng);
    for (int i = 0; i < n; ++i) {
      SampledWavelengths lambda = SampledWavelengths::rgb();
      const double light = estimateDirect(scene, hit, wo, lambda, sampler, false).g;
      const double mis = estimateDirectMIS(scene, hit, wo, lambda, sampler).g;
      sum[0] += light, sum2[0] += light * light, sum[1] += mis, sum2[1] += mis * mis;
    }
    double mean[2], variance[2];
    for (int k = 0; k < 2; ++k) mean[k] = sum[k] / n, variance[k] = sum2[k] / n - mean[k] * mean[k];
    INFO("light sampling " << mean[0] << " ± " << std::sqrt(variance[0] / n) << ", MIS " << mean[1] << " ± " << std::sqrt(variance[1] / n));
    CHECK(mean[1] > 0.5);  // a metal of F0 = 1 reflects most of the sky
    CHECK(std::abs(mean[1] - mean[0]) < 5 * std::sqrt((variance[0] + variance[1]) / n));
    if (alpha < 0.1f) CHECK(std::sqrt(variance[1]) < 0.1 * std::sqrt(variance[0]));
  }
}

TEST_CASE("closed diffuse furnace sphere: L = Le / (1 − ρ)") {
  // scenes/furnace.gltf: Le = 1, ρ = 0.5, so every pixel converges to 2.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/furnace.gltf");
  ImageRGB img = renderWith(*scene, "path", 12, 64);
  CHECK(mean(img) == Approx(2.0).epsilon(0.01));
  for (float v : img.data) REQUIRE(v == Approx(2.0f).epsilon(0.15));
  // Truncating the series after the first bounce gives Le + ρ·Le exactly: a check that depth
  // is counted in bounces.
  ImageRGB one = renderWith(*scene, "path", 12, 64, 0, 1);
  CHECK(mean(one) == Approx(1.5).epsilon(0.01));
  // Direct illumination alone: Le + ρ·Le as well (one bounce of emitted light).
  CHECK(mean(renderWith(*scene, "direct", 12, 64)) == Approx(1.5).epsilon(0.01));
  // --sampler sobol: each point is uniform, so the expectation stays 2 in every pixel; the
  // furnace check of the bidirectional methods (mean within 1%, the pixels' spread around 2 no
  // larger than the two seeds' noise says), 16×16 pixels at 64 spp. Its seeds are independent
  // scrambles; a sampler that reused one scramble for every pixel would also fail the spread.
  SECTION("--sampler sobol") {
    test::checkFurnace(renderWith(*scene, "path", 16, 64, 0, 64, "sobol", 1), renderWith(*scene, "path", 16, 64, 0, 64, "sobol", 2));
  }
}

TEST_CASE("glass slab in front of an emitter: transmittance (1 − R)/(1 + R) - Whitted = path") {
  // Normal incidence through two parallel interfaces, all internal reflections summed:
  // T = (1 − R)² Σ R^{2k} = (1 − R)/(1 + R), R = ((η − 1)/(η + 1))². Radiance scaling by η²
  // in and 1/η² out cancels.
  const float eta = 1.5f, Le = 3.0f;
  Scene scene;
  uint32_t glass = scene.addMaterial({"glass", std::make_unique<Dielectric>(eta), Spectrum(0), false});
  uint32_t emitter = scene.addMaterial({"emitter", std::make_unique<Lambertian>(ColorTexture(Spectrum(0))), Spectrum(Le), false});
  float s = 5.0f;
  // Front face (normal +z, towards the camera) at z = 0, back face (normal −z) at z = −0.2.
  scene.addMesh({{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}}, {}, {}, {0, 1, 2, 0, 2, 3}, glass);
  scene.addMesh({{-s, -s, -0.2f}, {-s, s, -0.2f}, {s, s, -0.2f}, {s, -s, -0.2f}}, {}, {}, {0, 1, 2, 0, 2, 3}, glass);
  scene.addMesh({{-s, -s, -1}, {s, -s, -1}, {s, s, -1}, {-s, s, -1}}, {}, {}, {0, 1, 2, 0, 2, 3}, emitter);
  Camera cam;
  cam.position = Vec3(0, 0, 2);
  cam.yfov = 0.01f;  // nearly normal incidence everywhere in the image
  scene.setCamera(cam);
  scene.commit();
  double R = std::pow((eta - 1) / (eta + 1), 2), T = (1 - R) / (1 + R);
  CHECK(mean(renderWith(scene, "whitted", 4, 1)) == Approx(Le * T).epsilon(1e-4));
  CHECK(mean(renderWith(scene, "path", 8, 1024)) == Approx(Le * T).epsilon(0.01));
  // Direct sees only emission: glass is black to it.
  CHECK(mean(renderWith(scene, "direct", 4, 1)) == 0.0);
}

TEST_CASE("a pile of glass plates: transmittance T/(N − (N−1)T) - the path tracer's variance is the binomial one (roulette divides out η²)") {
  // Three plates (η = 1.5, each transmitting T = (1 − R)/(1 + R) with all its internal
  // reflections) in front of an emitter: the pile of plates transmits T₃ = T/(3 − 2T) (Stokes'
  // formula for incoherent, lossless plates), 0.80 here. Under Fresnel sampling every camera path
  // either reaches the emitter with throughput exactly 1 (η² in, 1/η² out) or leaves: each sample
  // is Le or 0, so a pixel of n samples has variance Le² T₃(1 − T₃)/n, nothing more. A Russian
  // roulette on the raw throughput cut paths inside the third plate (throughput 1/η² there, at
  // the 5th bounce) with probability 56% and weighted the survivors by 2.25: variance ~7× the
  // binomial one. 16×16 pixels of 64 samples: the pixels' sample variance is within ±9% (1σ)
  // of its expectation; accepted in [0.7, 1.35]. The mean: within 4σ of Le·T₃ (σ = 0.1%).
  const float eta = 1.5f, Le = 1.0f;
  Scene scene;
  uint32_t glass = scene.addMaterial({"glass", std::make_unique<Dielectric>(eta), Spectrum(0), false});
  uint32_t emitter = scene.addMaterial({"emitter", std::make_unique<Lambertian>(ColorTexture(Spectrum(0))), Spectrum(Le), false});
  float s = 5.0f;
  for (int k = 0; k < 3; ++k) {  // plates 0.2 thick, 0.3 apart
    float front = -0.5f * k, back = front - 0.2f;
    scene.addMesh({{-s, -s, front}, {s, -s, front}, {s, s, front}, {-s, s, front}}, {}, {}, {0, 1, 2, 0, 2, 3}, glass);
    scene.addMesh({{-s, -s, back}, {-s, s, back}, {s, s, back}, {s, -s, back}}, {}, {}, {0, 1, 2, 0, 2, 3}, glass);
  }
  scene.addMesh({{-s, -s, -2}, {s, -s, -2}, {s, s, -2}, {-s, s, -2}}, {}, {}, {0, 1, 2, 0, 2, 3}, emitter);
  Camera cam;
  cam.position = Vec3(0, 0, 2);
  cam.yfov = 0.01f;  // nearly normal incidence everywhere in the image
  scene.setCamera(cam);
  scene.commit();
  const double R = std::pow((eta - 1) / (eta + 1), 2), T = (1 - R) / (1 + R), T3 = T / (3 - 2 * T);
  const int W = 16, n = 64;
  ImageRGB img = renderWith(scene, "path", W, n);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < W * W; ++i) {
    double v = img.data[3 * i + 1];
    sum += v, sum2 += v * v;
  }
  const double m = sum / (W * W), variance = (sum2 - W * W * m * m) / (W * W - 1);
  const double expectedVariance = Le * Le * T3 * (1 - T3) / n;
  INFO("mean " << m << " (T3 " << T3 << "), variance " << variance << ", binomial " << expectedVariance);
  CHECK(std::abs(m - Le * T3) < 4 * std::sqrt(expectedVariance / (W * W)));
  CHECK(variance / expectedVariance > 0.7);
  CHECK(variance / expectedVariance < 1.35);
}

TEST_CASE("Cornell box: path tracing limited to one bounce equals direct lighting (MIS is unbiased)") {
  // With max depth 1 the path tracer adds, at the first hit, next-event estimation and the
  // BSDF-sampled hit of the light, each weighted by the power heuristic: in expectation exactly
  // the direct integrator's light-sampling estimate. A wrong MIS weight breaks the equality.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  ImageRGB direct = renderWith(*scene, "direct", 32, 64);
  ImageRGB oneBounce = renderWith(*scene, "path", 32, 64, 0, 1);
  CHECK(mean(oneBounce) == Approx(mean(direct)).epsilon(0.01));
  // Whitted on a diffuse-only scene is local illumination too, sample for sample.
  CHECK(mean(renderWith(*scene, "whitted", 32, 64)) == Approx(mean(direct)).epsilon(1e-6));
  // Interreflection only adds light.
  CHECK(mean(renderWith(*scene, "path", 32, 64)) > 1.15 * mean(direct));
}

TEST_CASE("rendering is bit-identical whatever the thread count") {
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-spheres.gltf");
  ImageRGB a = renderWith(*scene, "path", 24, 4, 1), b = renderWith(*scene, "path", 24, 4, 2),
           c = renderWith(*scene, "path", 24, 4, 3);
  CHECK(a.data == b.data);
  CHECK(a.data == c.data);
  RenderOptions o;
  o.width = o.height = 24;
  o.spp = 4;
  o.seed = 2;
  auto path = makeIntegrator("path", {});
  ImageRGB d = render(*scene, *path, o, nullptr);
  CHECK(a.data != d.data);  // and the seed matters
  // The Sobol' sampler's points depend on the pixel and the sample number, never the thread.
  for (const char* integrator : {"path", "direct"}) {
    INFO(integrator);
    ImageRGB s1 = renderWith(*scene, integrator, 24, 4, 1, 64, "sobol"), s2 = renderWith(*scene, integrator, 24, 4, 2, 64, "sobol");
    CHECK(s1.data == s2.data);
    CHECK(s1.data != renderWith(*scene, integrator, 24, 4, 2, 64, "sobol", 2).data);
    CHECK(s1.data != renderWith(*scene, integrator, 24, 4, 2, 64, "independent").data);
  }
}

namespace {
// An integrator's pixels handed to it one at a time: PixelIntegrator's own LiPacket, which
// calls Li per pixel (the path tracer's Li traces its camera ray alone).
class OneAtATime final : public PixelIntegrator {
 public:
  explicit OneAtATime(std::unique_ptr<Integrator> inner) : inner_(std::move(inner)) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override {
    return pixel().Li(ray, scene, lambda, sampler);
  }
  int sobolSlots() const override { return pixel().sobolSlots(); }
  const char* name() const override { return "one pixel at a time"; }

 private:
  const PixelIntegrator& pixel() const { return dynamic_cast<const PixelIntegrator&>(*inner_); }
  std::unique_ptr<Integrator> inner_;
};
}  // namespace

TEST_CASE("path tracer: camera rays traced eight at a time (an Embree packet) make the image of one pixel at a time, bit for bit") {
  // A row of 21 pixels is two packets of eight and one of five. Glass and mirrors, a sky (camera
  // rays that leave the scene), a prism (spectral paths that drop their secondary wavelengths),
  // a depth limit.
  const std::string dir = std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/";
  struct Case {
    const char* file;
    bool spectral;
    int maxDepth;
    const char* sampler;
  };
  for (const Case& c : {Case{"cornell-spheres.gltf", false, 64, "independent"}, Case{"cornell-spheres.gltf", false, 64, "sobol"},
                        Case{"cornell-spheres.gltf", true, 3, "independent"}, Case{"sky.gltf", false, 64, "independent"},
                        Case{"prism.gltf", true, 64, "sobol"}}) {
    INFO(c.file << (c.spectral ? ", spectral" : "") << ", max depth " << c.maxDepth << ", " << c.sampler);
    auto scene = loadGltf(dir + c.file);
    RenderOptions o;
    o.width = 21, o.height = 13, o.spp = 3, o.threads = 2, o.spectral = c.spectral;
    // The scalar path tracer's packets (lanes off: they compute the same paths with different
    // rounding, tested in test_path_lanes.cpp).
    auto make = [&] { return test::makeWith("path", {{"max_depth", c.maxDepth}}, o, {{"sampler", c.sampler}, {"lanes", "off"}}); };
    auto packets = make();
    OneAtATime single(make());
    const ImageRGB a = render(*scene, *packets, o, nullptr), b = render(*scene, single, o, nullptr);
    CHECK(a.data == b.data);
    CHECK(mean(a) > 0.0);
  }
}

TEST_CASE("width alone keeps the camera's aspect ratio") {
  Camera cam;
  cam.aspectRatio = 4.0f / 3.0f;
  RenderOptions o;
  o.width = 320;
  resolveResolution(cam, o);
  CHECK(o.height == 240);
  RenderOptions p;
  resolveResolution(cam, p);
  CHECK(p.width == 512);
  CHECK(p.height == 384);
}

TEST_CASE("parallelFor on the pool: every item once, thread indices below the count - nested, concurrent, throwing - rays counted") {
  auto check = [](size_t count, int threads) {
    std::vector<std::atomic<int>> seen(count);
    std::atomic<int> badIndex{0};
    parallelFor(count, threads, [&](size_t i, int t) {
      ++seen[i];
      if (t < 0 || t >= threads) ++badIndex;
    });
    int wrong = badIndex.load();
    for (auto& n : seen) wrong += n.load() != 1;
    return wrong;
  };
  CHECK(check(10000, 2) == 0);
  CHECK(check(10000, 5) == 0);  // more threads than the last loop: the pool grows
  CHECK(check(3, 8) == 0);      // more threads than items
  // A loop inside a loop's item runs on threads of its own (the pool is busy): all items still once.
  std::atomic<int> inner{0};
  parallelFor(8, 2, [&](size_t, int) { parallelFor(100, 2, [&](size_t, int) { ++inner; }); });
  CHECK(inner == 800);
  // Two threads' loops at once: one has the pool, the other its own threads.
  int a = -1, b = -1;
  std::thread other([&] { a = check(20000, 2); });
  b = check(20000, 2);
  other.join();
  CHECK(a == 0);
  CHECK(b == 0);
  // An exception in an item reaches the caller, and the pool serves the next loop.
  CHECK_THROWS_AS(parallelFor(1000, 2, [](size_t i, int) {
                    if (i == 500) throw std::runtime_error("item 500");
                  }),
                  std::runtime_error);
  CHECK(check(1000, 2) == 0);
  // Rays counted on the pool's threads, which never exit, are in the total at once.
  const uint64_t before = Scene::raysTraced(), shadowBefore = Scene::shadowRaysTraced();
  parallelFor(1000, 2, [](size_t, int) { Scene::countRays(3, 2); });
  CHECK(Scene::raysTraced() - before == 5000);
  CHECK(Scene::shadowRaysTraced() - shadowBefore == 2000);
}

namespace {
// A learning integrator of known images, for the pixel loop's training hook. Each iteration's
// samples are `value[k]` (grey), plus U(0, 2) where `noisy[k]` (σ² = 1/3), or, where `echo[k]`,
// the pixel's value from the iterations before, as the loop hands it over.
struct Plan {
  std::vector<int> samples;
  std::vector<float> value;
  std::vector<bool> noisy, echo;
  bool replaces = false;
};
class Learner final : public PixelIntegrator, private TrainingHook {
 public:
  explicit Learner(Plan plan) : plan_(std::move(plan)) {}
  Spectrum Li(const Ray&, const Scene&, SampledWavelengths&, Sampler& sampler) const override {
    const size_t k = size_t(iteration_);
    return Spectrum(plan_.value[k] + (plan_.noisy[k] ? 2 * sampler.get1D() : 0.0f));
  }
  void LiPacket(CameraSample* samples, int n, const Scene& scene) const override {
    for (int i = 0; i < n; ++i) {
      CameraSample& c = samples[i];
      c.L = plan_.echo[size_t(iteration_)] ? Spectrum(c.pixelEstimate) : Li(c.ray, scene, *c.lambda, *c.sampler);
      int seen = maxThread_.load();
      while (c.thread > seen && !maxThread_.compare_exchange_weak(seen, c.thread)) {}
    }
  }
  TrainingHook* training() override { return this; }
  const char* name() const override { return "learner"; }

  std::vector<int> indices;
  std::vector<IterationReport> reports;
  int threads = 0;
  int maxThread() const { return maxThread_.load(); }

 private:
  Iteration beforeIteration(const Scene&, int index, const RenderOptions&, int threadCount, const Budget&) override {
    indices.push_back(index);
    threads = threadCount;
    iteration_ = index;
    if (size_t(index) >= plan_.samples.size()) return {};
    return {plan_.samples[size_t(index)], size_t(index) + 1 == plan_.samples.size(), plan_.replaces};
  }
  void afterIteration(const IterationReport& r) override { reports.push_back(r); }

  Plan plan_;
  int iteration_ = 0;
  mutable std::atomic<int> maxThread_{-1};
};

double imageMean(const ImageRGB& image) {
  double s = 0;
  for (float v : image.data) s += v;
  return s / double(image.data.size());
}
}  // namespace

TEST_CASE("pixel loop: an integrator that learns renders in iterations, its hook called between them, their images combined by inverse variance") {
  auto scene = floorScene(1.0f, 0.5f);
  RenderOptions o;
  o.width = o.height = 32;
  o.threads = 2;
  RenderInfo info;

  SECTION("exact images weigh by their sample counts: (2·1 + 3·6)/5 = 4; the last alone where it replaces") {
    o.spp = 5;
    Learner both(Plan{{2, 3}, {1, 6}, {false, false}, {false, false}});
    ImageRGB image = render(*scene, both, o, &info);
    for (float v : image.data) REQUIRE(v == Approx(4.0f).epsilon(1e-6));
    CHECK(info.spp == 5);
    CHECK(both.indices == std::vector<int>{0, 1});  // not called after the last iteration
    REQUIRE(both.reports.size() == 2);
    CHECK(both.reports[0].samples == 2);
    CHECK(both.reports[1].least == 3);
    CHECK(both.reports[1].variance == 0.0);
    CHECK(both.reports[1].seconds >= both.reports[1].trainingSeconds);
    CHECK(both.threads == 2);
    CHECK(both.maxThread() >= 0);
    CHECK(both.maxThread() < 2);
    Learner last(Plan{{2, 3}, {1, 6}, {false, false}, {false, false}, /*replaces=*/true});
    for (float v : render(*scene, last, o, nullptr).data) REQUIRE(v == 6.0f);
  }

  SECTION("the hook sees each pixel's value so far; an exact iteration outweighs a noisy one; σ² of one sample is measured") {
    // Iteration 0: U(0, 2), σ² = 1/3, one sample per pixel (σ² then from diagonal neighbours'
    // differences) or two. Iteration 1 repeats each pixel's value so far: σ² = 0, so the image
    // is iteration 0's, pixel for pixel.
    for (int first : {1, 2}) {
      INFO("iteration 0 with " << first << " samples per pixel");
      o.spp = first;
      Learner alone(Plan{{first}, {0}, {true}, {false}});
      ImageRGB noisy = render(*scene, alone, o, nullptr);
      o.spp = first + 3;
      Learner echo(Plan{{first, 3}, {0, 0}, {true, false}, {false, true}});
      ImageRGB image = render(*scene, echo, o, &info);
      for (size_t i = 0; i < image.data.size(); ++i) REQUIRE(image.data[i] == Approx(noisy.data[i]).epsilon(1e-6));
      // The pooled σ² has ≈ 1024 degrees of freedom: its standard error is σ²·√(2/1024) ≈ 0.015.
      REQUIRE(echo.reports.size() == 2);
      CHECK(echo.reports[0].variance == Approx(1.0 / 3).margin(5 * 0.0147));
      CHECK(echo.reports[1].variance < 1e-12);
      CHECK(imageMean(noisy) == Approx(1.0).margin(5 * std::sqrt(1.0 / 3 / (1024.0 * first))));
    }
  }

  SECTION("the hook ends the render: with fewer passes than asked for, or none") {
    o.spp = 8;
    Learner shorter(Plan{{1, 1}, {2, 2}, {false, false}, {false, false}});
    for (float v : render(*scene, shorter, o, &info).data) REQUIRE(v == 2.0f);
    CHECK(info.spp == 2);
    Learner none(Plan{{}, {}, {}, {}});
    for (float v : render(*scene, none, o, &info).data) REQUIRE(v == 0.0f);
    CHECK(info.spp == 0);
    CHECK(none.reports.empty());
  }

  SECTION("its slices would not add up: a sliced render is refused") {
    o.spp = 4;
    o.rangeBegin = 0, o.rangeEnd = 2;
    Learner l(Plan{{4}, {1}, {false}, {false}});
    CHECK_THROWS_WITH(render(*scene, l, o, nullptr), Contains("learns between iterations"));
  }
}
