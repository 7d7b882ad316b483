// The contract every registered integrator keeps, checked by looping over the registry: an
// integrator gets these tests by being registered, with no list in any test to edit. Ambient
// occlusion, an integrator that exists only in this test binary and registers itself below,
// proves it: every loop here must meet it, and it must pass what they check.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <set>

#include "bsdfs/lambertian.h"
#include "core/budget.h"
#include "core/sampling.h"
#include "integrators/registry.h"
#include "lights/point_light.h"
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

const IntegratorRegistration ambientOcclusion(IntegratorEntry(
    "ao", "ambient occlusion (test only): the open fraction of the hemisphere within a distance", IntegratorFamily::Pixel,
    "spp", {params::spp(), occlusionDistance()},
    [](const ParamSet& p, const RenderOptions&) { return std::make_unique<AmbientOcclusion>(float(p.real("distance"))); }));

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

}  // namespace

TEST_CASE("contract: every integrator renders the same bits on 1 and 2 threads") {
  // The mirror-and-glass box: every kind of vertex. Streams are keyed by pixel and sample (or
  // path index), and sums are exact, so the thread count must not show.
  auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-spheres.gltf");
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
