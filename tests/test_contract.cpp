// The contract every registered integrator keeps, checked by looping over the registry: an
// integrator gets these tests by being registered, with no list in any test to edit. Ambient
// occlusion, an integrator that exists only in this test binary and registers itself below,
// proves it: every loop here must meet it, and it must pass what they check.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <set>

#include "bsdfs/dielectric.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/mirror.h"
#include "core/budget.h"
#include "core/interrupt.h"
#include "core/sampling.h"
#include "integrators/registry.h"
#include "lights/directional_light.h"
#include "lights/environment_light.h"
#include "lights/point_light.h"
#include "lights/spot_light.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

// Ambient occlusion: the fraction of the cosine-weighted hemisphere on the side the camera sees
// that is open within `distance`. Estimated by one cosine-sampled visibility ray per sample, so
// the estimate is unbiased, and exactly 1 (or 0) where every direction is open (or closed).
class AmbientOcclusion final : public PixelIntegrator {
 public:
  explicit AmbientOcclusion(float distance) : distance_(distance) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths&, Sampler& sampler) const override {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) return Spectrum(0.0f);
    const Frame frame(glm::dot(hit.ng, ray.d) < 0 ? hit.ng : -hit.ng);
    const Vec3 wi = frame.toWorld(sampleCosineHemisphere(sampler.get2D()));
    return Spectrum(scene.visible(hit, wi, distance_) ? 1.0f : 0.0f);
  }
  const char* name() const override { return "ao"; }

 private:
  float distance_;
};

ParamSpec occlusionDistance() {
  ParamSpec s("distance", ParamType::Real, "occlusion distance (m)", "1");
  s.lo = 0, s.hi = 1e6, s.openLow = true;
  return s;
}

IntegratorEntry ambientOcclusionEntry() {
  IntegratorEntry e(
      "ao", "ambient occlusion (test only): the open fraction of the hemisphere within a distance", IntegratorFamily::Pixel,
      "spp", {params::spp(), occlusionDistance()},
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<AmbientOcclusion>(float(p.real("distance"))); });
  e.converges = Converges::kOther;  // occlusion, not radiance: the closed forms of light transport do not apply
  return e;
}
const IntegratorRegistration ambientOcclusion(ambientOcclusionEntry());

// An entry's parameters with `work` samples, passes or iterations, and small photon counts and
// meshes by parameter name, whichever integrator declares them.
ParamSet cheap(const IntegratorEntry& e, int work) {
  ParamSet p = e.defaults();
  if (const ParamSpec* budget = e.budgetParam()) p.setNumber(budget->name, work);
  for (const auto& [name, value] : {std::pair<const char*, double>{"photons", 2000}, {"caustic_photons", 2000},
                                    {"photons_per_pass", 2000}, {"patches", 100}})
    if (p.has(name)) p.setNumber(name, value);
  return p;
}

// As `photonlab render` does it: scene-derived defaults resolved, then the integrator made and run.
ImageRGB renderEntry(const Scene& scene, const IntegratorEntry& e, ParamSet p, RenderOptions o, RenderInfo* info) {
  if (e.resolve) e.resolve(scene, o.width, o.height, p);
  if (p.has("spp")) o.spp = int(p.integer("spp"));
  auto integrator = makeIntegrator(e.name, p, o);
  return integrator->render(scene, o, info);
}

bool identicalBits(const ImageRGB& a, const ImageRGB& b) {
  return a.width == b.width && a.height == b.height && a.data.size() == b.data.size() &&
         std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
}

// The degenerate cases of the robustness test in one scene: collinear and coincident triangles,
// a zero-area emitter, a zero-power light beside a real one.
std::unique_ptr<Scene> hostileScene() {
  auto scene = std::make_unique<Scene>();
  uint32_t floor = lambertian(*scene, 0.5f);
  addQuad(*scene, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, floor);
  scene->addMesh({{0, 0.5f, 0}, {0.1f, 0.5f, 0}, {0.2f, 0.5f, 0}}, {}, {}, {0, 1, 2}, floor);
  scene->addMesh({{0, 0.3f, 0}, {0, 0.3f, 0}, {0, 0.3f, 0}}, {}, {}, {0, 1, 2}, floor);
  uint32_t emitter = scene->addMaterial({"emitter", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.5f))), Spectrum(10), false});
  scene->addMesh({{0, 0.8f, 0}, {0, 0.8f, 0}, {0.1f, 0.8f, 0}}, {}, {}, {0, 1, 2}, emitter);
  scene->addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(1.0f)));
  scene->addLight(std::make_unique<PointLight>(Vec3(0, 1, 0.5f), Spectrum(0.0f)));
  scene->setCamera(lookingDown(2.0f));
  scene->commit();
  return scene;
}

// ----- closed forms ------------------------------------------------------------------------

// A scene whose every pixel's expectation is known: the green channel of `expected` (grey scenes).
struct ClosedForm {
  std::string name;
  std::unique_ptr<Scene> scene;
  ImageRGB expected;
};

constexpr int kClosedFormSize = 16;  // pixels a side

// The closed furnace (scenes/furnace.gltf): a sphere of emission Le = 1 and albedo ρ = 0.5 around
// the camera. Radiance is Le/(1 − ρ) = 2 everywhere (the series Le Σ ρᵏ); direct lighting alone
// is Le + ρ·E/π with E = π·Le inside a uniformly emitting closed surface: 1.5.
ClosedForm furnace(Converges converges) {
  ClosedForm c{"the closed furnace", loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/furnace.gltf"),
               ImageRGB(kClosedFormSize, kClosedFormSize)};
  const float L = converges == Converges::kDirectLighting ? 1.5f : 2.0f;
  for (float& v : c.expected.data) v = L;
  return c;
}

// A diffuse floor (ρ = 0.8) under one light of the given kind, seen from 0.9 m above its centre
// over [−1.2, 1.2]²; with nothing else to bounce from, L = ρ/π·E(x), E from the light's closed
// form, averaged over each pixel's footprint. The floor reaches 5 m from the centre (2 m under
// the sky, whose light paths start on a disc around the whole scene), so that a gather radius
// of a few 15 cm pixel footprints around a pixel in view stays on it.
ClosedForm litFloor(LightType kind) {
  constexpr float kRho = 0.8f;
  const float half = kind == LightType::kInfinite ? 2.0f : 5.0f;
  auto scene = std::make_unique<Scene>();
  addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, lambertian(*scene, kRho));
  std::function<double(const Vec3&)> E;
  std::string name;
  switch (kind) {
    case LightType::kDeltaPosition:
      // A glTF spot 10 m up, I = 100 W/sr, pointing down, full intensity within 0.3 rad of its
      // axis (the view's corners are 0.17 rad off it, a gather radius's reach 0.25), off beyond
      // 0.35 rad: E = I cosθ/r² over the view, and its photons and light paths land on the
      // floor. Far, so that E is smooth: a gather radius of a few pixel footprints blurs it by
      // well under 1%.
      scene->addLight(std::make_unique<SpotLight>(Vec3(0, 10, 0), Vec3(0, -1, 0), Spectrum(100.0f), 0.3f, 0.35f));
      E = [](const Vec3& x) {
        const double r2 = 100.0 + x.x * x.x + x.z * x.z;
        return 100.0 * (10.0 / std::sqrt(r2)) / r2;
      };
      name = "a spot light";
      break;
    case LightType::kDeltaDirection:  // E⊥ = 2 W/m², 30° from the vertical: E = 2 cos 30°
      scene->addLight(std::make_unique<DirectionalLight>(Vec3(0.5f, -std::sqrt(3.0f) / 2, 0), Spectrum(2.0f)));
      E = [](const Vec3&) { return 2.0 * std::sqrt(3.0) / 2; };
      name = "a directional light";
      break;
    case LightType::kArea: {
      // A 6 m × 6 m one-sided emitter 5 m up facing down, Le = 2: E by Lambert's formula, smooth
      // over the view for the same reason as the spot's.
      const std::vector<Vec3> quad = {{-3, 5, -3}, {3, 5, -3}, {3, 5, 3}, {-3, 5, 3}};
      const uint32_t m = scene->addMaterial({"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(2.0f), false});
      addQuad(*scene, quad[0], quad[1], quad[2], quad[3], m);  // counter-clockwise from below: faces the floor
      E = [quad](const Vec3& x) {
        // E = (L/2) Σ βᵢ n·unit(uᵢ × uᵢ₊₁) (Lambert), independent of the renderer's sampling.
        double sum = 0;
        for (size_t i = 0; i < quad.size(); ++i) {
          const glm::dvec3 a = glm::normalize(glm::dvec3(quad[i] - x)), b = glm::normalize(glm::dvec3(quad[(i + 1) % 4] - x));
          sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::normalize(glm::cross(a, b)).y;
        }
        return 0.5 * 2.0 * std::abs(sum);
      };
      name = "an area light";
      break;
    }
    case LightType::kInfinite:  // a constant sky L = 0.7 over the open floor: E = π·L
      scene->addLight(EnvironmentLight::constant(Spectrum(0.7f)));
      E = [](const Vec3&) { return kPi * 0.7; };
      name = "a constant sky";
      break;
  }
  scene->setCamera(lookingDown(0.9f, 2.0f * std::atan(1.2f / 0.9f)));
  scene->commit();
  ImageRGB expected = expectedFloorImage(*scene, kClosedFormSize, kClosedFormSize, [&](const Vec3& x) { return kRho / kPi * E(x); }, 8);
  return {"a floor under " + name, std::move(scene), std::move(expected)};
}

// Two seeds' renders against the expectation e, green channel.
//   se:   the standard error of the two seeds' image mean, from the seed-to-seed differences of
//         4×4-pixel region means (16 regions: neighbours sharing photons or merges are inside
//         one region, so regions are nearly independent even for density estimation);
//   p99z: the 99th percentile over pixels of |z|, z = (x̄ − e)/√(σ̂²/2 + (δe)²), σ̂² one seed's
//         variance from the seeds' differences over the pixel's 3×3 neighbourhood, δ = 1%: a
//         pixel may be off by a discretisation or kernel bias of about 1% on top of its noise.
struct ClosedFormAgreement {
  double mean = 0, expected = 0, se = 0, p99z = 0;
};
ClosedFormAgreement agreement(const ImageRGB& a, const ImageRGB& b, const ImageRGB& e) {
  const int W = e.width, H = e.height, B = 4;
  auto g = [](const ImageRGB& img, int x, int y) { return double(img.at(x, y).g); };
  ClosedFormAgreement r;
  double d2Regions = 0;
  int regionCount = 0;
  for (int by = 0; by < H / B; ++by)
    for (int bx = 0; bx < W / B; ++bx) {
      double d = 0;
      for (int y = by * B; y < (by + 1) * B; ++y)
        for (int x = bx * B; x < (bx + 1) * B; ++x) d += (g(a, x, y) - g(b, x, y)) / (B * B);
      d2Regions += d * d, ++regionCount;
    }
  // Var(region mean of one seed) ≈ mean(d²)/2; the image mean of two seeds averages R regions × 2.
  r.se = std::sqrt(d2Regions / regionCount / 2 / (2.0 * regionCount));
  std::vector<double> z;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double mean = (g(a, x, y) + g(b, x, y)) / 2, expected = g(e, x, y);
      const double sigma2 = neighbourhoodVariance(a, b, x, y) / 2 + 1e-4 * expected * expected;
      z.push_back(std::abs(mean - expected) / std::sqrt(sigma2));
      r.mean += mean / (W * H), r.expected += expected / (W * H);
    }
  std::sort(z.begin(), z.end());
  r.p99z = z[size_t(0.99 * double(z.size() - 1))];
  return r;
}

// Renders `form` with `entry` at its defaults, its budget from 4 and its refinement parameters
// doubled until the image mean's standard error is at most 1% of the expectation (at most 2⁸
// times), seeds 1 and 2; then holds it to the closed form: the image mean within 4 standard
// errors plus 1% (a discretisation or kernel bias: PPM's first passes gather over 75 cm at this
// resolution and blur E by ~0.7%), and every pixel's |z| at the 99th percentile below 4.5 (3.25
// would be t₉'s; the neighbourhood's noise is uneven). A 2% bias fails it: PPM did, before the
// floor was wide enough for its radius.
void checkClosedForm(const IntegratorEntry& entry, const ClosedForm& form, const std::string& photonTarget = "") {
  INFO(entry.name << " on " << form.name << (photonTarget.empty() ? "" : ", photon target " + photonTarget));
  ParamSet p = entry.defaults();
  if (!photonTarget.empty()) p.setText("photon_target", photonTarget);
  std::vector<std::string> refinement = entry.refinement;
  if (refinement.empty()) refinement.push_back(entry.budgetParam()->name);
  if (const ParamSpec* budget = entry.budgetParam()) p.setNumber(budget->name, 4);
  RenderOptions o;
  o.width = o.height = kClosedFormSize;
  ClosedFormAgreement r;
  for (int doubling = 0;; ++doubling) {
    o.seed = 1;
    const ImageRGB a = renderEntry(*form.scene, entry, p, o, nullptr);
    o.seed = 2;
    const ImageRGB b = renderEntry(*form.scene, entry, p, o, nullptr);
    r = agreement(a, b, form.expected);
    if (r.se <= 0.01 * r.expected || doubling == 8) break;
    for (const std::string& name : refinement) p.setNumber(name, 2 * double(p.integer(name)));
  }
  std::string used;
  for (const std::string& name : refinement) used += name + " " + std::to_string(p.integer(name)) + " ";
  INFO(used << "-> mean " << r.mean << " against " << r.expected << " (standard error " << r.se << "), p99 |z| " << r.p99z);
  CHECK(r.se <= 0.01 * r.expected);  // it converges at a budget a test can afford
  CHECK(std::abs(r.mean - r.expected) <= 4 * r.se + 0.01 * r.expected);
  CHECK(r.p99z < 4.5);
}

}  // namespace

// A box lit by an area light, with a mirror cube and a glass cube in it: every kind of vertex
// (diffuse, specular reflection, refraction and total internal reflection) in 58 triangles, so
// that a method that meshes the scene (radiosity: a patch or more per triangle) stays small.
std::unique_ptr<Scene> mirrorAndGlassBox() {
  auto scene = std::make_unique<Scene>();
  auto cube = [&](Vec3 lo, Vec3 hi, uint32_t m) {  // outward faces (counter-clockwise seen from outside)
    addQuad(*scene, {lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, m);
    addQuad(*scene, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, m);
    addQuad(*scene, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, m);
    addQuad(*scene, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, m);
    addQuad(*scene, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z}, m);
    addQuad(*scene, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, m);
  };
  const uint32_t wall = lambertian(*scene, 0.6f);
  const uint32_t red = scene->addMaterial({"red", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.6f, 0.1f, 0.1f))), Spectrum(0), false});
  const uint32_t mirror = scene->addMaterial({"mirror", std::make_unique<Mirror>(ColorTexture(Spectrum(0.9f))), Spectrum(0), false});
  const uint32_t glass = scene->addMaterial({"glass", std::make_unique<Dielectric>(1.5f), Spectrum(0), false});
  const uint32_t lamp = scene->addMaterial({"lamp", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(10), false});
  addQuad(*scene, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}, wall);  // floor
  addQuad(*scene, {-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, wall);      // ceiling
  addQuad(*scene, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1}, wall);  // back
  addQuad(*scene, {-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, red);   // left
  addQuad(*scene, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}, wall);      // right
  addQuad(*scene, {-0.3f, 0.99f, -0.3f}, {0.3f, 0.99f, -0.3f}, {0.3f, 0.99f, 0.3f}, {-0.3f, 0.99f, 0.3f}, lamp);  // facing down
  cube({-0.7f, -1, -0.6f}, {-0.2f, -0.4f, -0.1f}, mirror);
  cube({0.1f, -1, 0}, {0.6f, -0.5f, 0.5f}, glass);
  Camera cam;
  cam.position = Vec3(0, 0, 3.4f);
  cam.forward = Vec3(0, 0, -1);
  cam.up = Vec3(0, 1, 0);
  cam.right = glm::cross(cam.forward, cam.up);
  cam.yfov = 0.8f;
  scene->setCamera(cam);
  scene->commit();
  return scene;
}

TEST_CASE("contract: every integrator renders the same bits on 1 and 2 threads") {
  // Streams are keyed by pixel and sample (or path index), and sums are exact, so the thread
  // count must not show.
  auto scene = mirrorAndGlassBox();
  std::set<std::string> seen;
  for (const IntegratorEntry* e : integrators()) {
    INFO(e->name);
    RenderOptions o;
    o.width = o.height = 12;
    o.seed = 3;
    o.threads = 1;
    RenderInfo one, two;
    const ImageRGB a = renderEntry(*scene, *e, cheap(*e, 2), o, &one);
    o.threads = 2;
    const ImageRGB b = renderEntry(*scene, *e, cheap(*e, 2), o, &two);
    CHECK(identicalBits(a, b));
    CHECK(meanOf(a) > 0);  // lit: two black films would agree vacuously
    seen.insert(e->name);
  }
  CHECK(seen.count("ao"));  // the test-only integrator was met without being listed
  CHECK(seen.size() == integrators().size());
}

TEST_CASE("contract: no integrator puts a NaN or an infinity on the film of a degenerate scene") {
  auto scene = hostileScene();
  for (const IntegratorEntry* e : integrators()) {
    INFO(e->name);
    RenderOptions o;
    o.width = o.height = 10;
    RenderInfo info;
    const ImageRGB image = renderEntry(*scene, *e, cheap(*e, 3), o, &info);
    CHECK(info.nonFiniteSamples == 0);
    size_t bad = 0;
    double sum = 0;
    for (float v : image.data) bad += !std::isfinite(v), sum += v;
    CHECK(bad == 0);
    CHECK(sum > 0);  // something is lit: a blank film would pass the finiteness check vacuously
  }
}

TEST_CASE("contract: every integrator stops when its time budget ends - with a finite image - and says so") {
  // A time budget alone (its work unlimited, as `--time` without a count gives it), read from an
  // injected clock: every reading advances 1 ms, so the budget is 200 polls of work. An
  // integrator that did not poll its budget would never return (ctest's timeout fails it).
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  for (const IntegratorEntry* e : integrators()) {
    INFO(e->name);
    SteppingClock clock(1e-3);
    RenderOptions o;
    o.width = o.height = 16;
    o.threads = 1;
    o.timeLimit = 0.2;
    o.clock = &clock;
    ParamSet p = cheap(*e, 1);
    if (const ParamSpec* budget = e->budgetParam()) p.unset(budget->name);
    if (e->resolve) e->resolve(*scene, o.width, o.height, p);
    o.spp = p.isSet("spp") ? int(p.integer("spp")) : 0;  // unset: until the budget ends (experiment/config.cpp)
    RenderInfo info;
    const ImageRGB image = makeIntegrator(e->name, p, o)->render(*scene, o, &info);
    CHECK(info.timeUp);
    CHECK(info.seconds >= o.timeLimit);
    size_t bad = 0;
    for (float v : image.data) bad += !std::isfinite(v);
    CHECK(bad == 0);
  }
}

namespace {
// Time is the work polled, as SteppingClock, and at reading `at` an interrupt arrives (as Ctrl-C
// raises it): the readings after it are the polls the render makes before it returns.
class InterruptingClock final : public Clock {
 public:
  explicit InterruptingClock(uint64_t at) : at_(at) {}
  double seconds() override {
    const uint64_t n = ticks_.fetch_add(1, std::memory_order_relaxed) + 1;
    if (n == at_) requestInterrupt();
    return double(n) * 1e-3;
  }
  uint64_t readingsAfter() const { return ticks_.load() > at_ ? ticks_.load() - at_ : 0; }
  bool reached() const { return ticks_.load() >= at_; }

 private:
  uint64_t at_;
  std::atomic<uint64_t> ticks_{0};
};
}  // namespace

TEST_CASE("contract: every integrator stops within a few polls of an interrupt - in preprocessing or rendering - with a finite image") {
  // Work no test could wait for (2^20 samples, passes or iterations), a time budget that never
  // ends, and an interrupt at the clock's 3rd reading (in preprocessing where there is any) or
  // its 60th. One thread: the poll that reads the interrupt sees it, each work item still queued
  // in that parallel loop (at most a row each, 16 here) polls once before any work and returns,
  // and the loops around it return after a poll each (8 allowed). The latency is counted in
  // polls, each at most a packet of pixels, a chunk of light paths or a slice of a build.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  for (const IntegratorEntry* e : integrators()) {
    for (uint64_t at : {3, 60}) {
      INFO(e->name << ", interrupted at the clock's reading " << at);
      clearInterrupt();
      InterruptingClock clock(at);
      RenderOptions o;
      o.width = o.height = 16;
      o.threads = 1;
      o.timeLimit = 1e9;
      o.clock = &clock;
      RenderInfo info;
      const ImageRGB image = renderEntry(*scene, *e, cheap(*e, 1 << 20), o, &info);
      clearInterrupt();
      REQUIRE(clock.reached());
      CHECK(info.interrupted);
      CHECK(clock.readingsAfter() <= uint64_t(o.height) + 8);
      size_t bad = 0;
      for (float v : image.data) bad += !std::isfinite(v);
      CHECK(bad == 0);
    }
  }
}

TEST_CASE("contract: an integrator that declares a slice unit merges its slices into the whole render's bits") {
  // Slices of the samples (or passes) 0..4 interleaved as 0:5:2 and 1:5:2, added up exactly as
  // `photonlab merge` does, must be the single render's image bit for bit.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-box.gltf");
  std::set<std::string> sliced;
  for (const IntegratorEntry* e : integrators()) {
    if (e->sliceUnit.empty()) continue;
    INFO(e->name << " sliced by " << e->sliceUnit);
    RenderOptions o;
    o.width = 12, o.height = 10;
    o.seed = 7;
    const ParamSet p = cheap(*e, 5);
    RenderInfo whole;
    const ImageRGB full = renderEntry(*scene, *e, p, o, &whole);
    std::shared_ptr<const RenderSlice> parts[2];
    for (int k = 0; k < 2; ++k) {
      RenderOptions s = o;
      s.rangeBegin = k, s.rangeEnd = 5, s.rangeStep = 2;
      RenderInfo info;
      renderEntry(*scene, *e, p, s, &info);
      REQUIRE(info.slice);
      parts[k] = info.slice;
    }
    RenderSlice merged = *parts[0];
    for (size_t i = 0; i < merged.sums.size(); ++i) merged.sums[i].add(parts[1]->sums[i]);
    for (size_t i = 0; i < merged.splats.size(); ++i) merged.splats[i].add(parts[1]->splats[i]);
    for (size_t i = 0; i < merged.counts.size(); ++i) merged.counts[i] += parts[1]->counts[i];
    merged.begin = 0, merged.step = 1;
    CHECK(identicalBits(merged.mean(), full));
    // And one slice alone is not the whole (the check can fail).
    CHECK_FALSE(identicalBits(parts[0]->mean(), full));
    sliced.insert(e->name);
  }
  CHECK(sliced.count("ao"));
  CHECK(sliced.count("pppm"));
}

TEST_CASE("contract: the test-only integrator meets its closed forms exactly") {
  // Over an open floor every direction is open: AO = 1 at every pixel, each sample exactly 1.
  // Inside the furnace's closed sphere every direction meets the sphere: AO = 0 exactly.
  RenderOptions o;
  o.width = o.height = 8;
  const IntegratorEntry& ao = integratorEntry("ao");
  {
    Scene plane;
    addQuad(plane, {-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, lambertian(plane, 0.5f));
    plane.setCamera(lookingDown(1.0f));
    plane.commit();
    const ImageRGB image = renderEntry(plane, ao, cheap(ao, 16), o, nullptr);
    for (float v : image.data) CHECK(v == 1.0f);
  }
  auto furnace = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/furnace.gltf");
  ParamSet closed = cheap(ao, 16);
  closed.setNumber("distance", 1e6);
  for (float v : renderEntry(*furnace, ao, closed, o, nullptr).data) CHECK(v == 0.0f);
}

TEST_CASE("contract: every integrator of radiance renders the closed furnace's L = Le/(1 − ρ) per pixel", "[long]") {
  // Direct lighting's integrators are held to Le + ρLe instead; the others (the test-only ambient
  // occlusion) are not radiance, and the furnace says nothing about them.
  std::set<std::string> judged;
  for (const IntegratorEntry* e : integrators()) {
    if (e->converges == Converges::kOther) continue;
    checkClosedForm(*e, furnace(e->converges));
    judged.insert(e->name);
  }
  CHECK(judged.count("path"));
  CHECK(!judged.count("ao"));
}

TEST_CASE("contract: every integrator of radiance renders a lit floor's ρ/π·E per pixel - under every kind of light it carries", "[long]") {
  // One light of each LightType: delta position, delta direction, area, infinite. An integrator
  // that declares a kind it does not carry (radiosity and the sky) is not rendered with it.
  int judged = 0;
  for (LightType kind : {LightType::kDeltaPosition, LightType::kDeltaDirection, LightType::kArea, LightType::kInfinite}) {
    const ClosedForm form = litFloor(kind);
    for (const IntegratorEntry* e : integrators()) {
      if (e->converges == Converges::kOther || !(e->carries & lightTypeBit(kind))) continue;
      checkClosedForm(*e, form);
      ++judged;
      // The photons of a sky and the sun, aimed at the view by default: over the scene's disc too.
      if (e->defaults().has("photon_target") && (kind == LightType::kDeltaDirection || kind == LightType::kInfinite))
        checkClosedForm(*e, form, "scene");
    }
  }
  CHECK(judged >= 4 * 12);
}
