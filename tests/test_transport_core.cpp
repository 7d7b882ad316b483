// The transport core's light-side pieces: the camera as an emitter of importance, and the
// lights' emission densities, which light tracing and bidirectional methods weigh strategies
// with. Expected values come from closed forms (the film's area, unit integrals of densities).
#include <catch2/catch.hpp>

#include "core/rng.h"
#include "core/sampling.h"
#include "lights/area_light.h"
#include "lights/directional_light.h"
#include "lights/point_light.h"
#include "lights/spot_light.h"
#include "lights/warn_spotlight.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

TEST_CASE("camera importance: raster() inverts generateRay() - We integrates to 1 over the film - pdfWe to 1") {
  Camera c = lookingDown(2.0f, 0.9f);
  const int W = 40, H = 30;
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    float x = rng.uniform() * W, y = rng.uniform() * H;
    Vec2 r;
    REQUIRE(c.raster(c.generateRay(x, y, W, H).d, W, H, &r));
    CHECK(r.x == Approx(x).margin(1e-3));
    CHECK(r.y == Approx(y).margin(1e-3));
  }
  // ∫ We cosθ dω = 1 and ∫ pdfDir dω = 1 over the sphere, by uniform sphere sampling (an
  // estimate with standard deviation ~0.3/√N: 0.1% at N = 10⁶ for this field of view).
  const int N = 1000000;
  double we = 0, pdf = 0;
  for (int i = 0; i < N; ++i) {
    Vec3 d = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    float pos, dir;
    c.pdfWe(d, W, H, &pos, &dir);
    we += c.We(d, W, H) * std::max(0.0f, glm::dot(d, c.forward)) * 4 * kPi;
    pdf += dir * 4 * kPi;
  }
  CHECK(we / N == Approx(1.0).epsilon(0.005));
  CHECK(pdf / N == Approx(1.0).epsilon(0.005));
  // The film's area at distance 1: (2 tan(fov/2))² · aspect.
  CHECK(c.filmArea(W, H) == Approx(4 * std::tan(0.45) * std::tan(0.45) * 4.0 / 3.0).epsilon(1e-6));
  // A point behind the camera, or outside the view, has no connection.
  CameraSample cs;
  CHECK_FALSE(c.sampleWi(Vec3(0, 3, 0), W, H, &cs));
  CHECK_FALSE(c.sampleWi(Vec3(10, 0, 0), W, H, &cs));
  REQUIRE(c.sampleWi(Vec3(0, 0, 0), W, H, &cs));
  CHECK(cs.raster.x == Approx(W / 2.0f));
  CHECK(cs.pdf == Approx(4.0f));  // d²/cosθ = 2²/1
}

TEST_CASE("camera importance: a ray made on the film's far edge keeps its direction density 1/(A cos³θ)") {
  // A pixel's jitter x + u with u < 1 rounds to the width in float when 1 − u is at most half
  // the float spacing at x (2⁻¹⁶ at x = 511: 511 + (1 − 2⁻²⁴) is 512.0f): generateRay then makes
  // a ray on the film's far edge, which pdfWe's film, [0, W) × [0, H), leaves out (density 0:
  // measured for each position below). The bidirectional camera subpath's first density
  // (generatedPdfDir) must still be the film's, 1/(A cos³θ) with A the film's area at distance 1
  // (dω = dA cos³θ at distance 1/cosθ): here compared with pdfWe just inside the edge, where the
  // density is continuous (2·10⁻³ pixel away: relative change ~10⁻⁶).
  const int W = 512, H = 512;
  REQUIRE(float(W - 1) + (1.0f - 0x1p-24f) == float(W));
  Camera c = lookingDown(2.0f, 0.9f);
  const float tanHalf = std::tan(0.45f);
  for (const Vec2& edge : {Vec2(W, 200), Vec2(200, H), Vec2(W, H), Vec2(0, H), Vec2(W, 0)}) {
    INFO("film position " << edge.x << ", " << edge.y);
    const Vec3 d = c.generateRay(edge.x, edge.y, W, H).d;
    const Vec2 inside(std::min(edge.x, W - 0.002f), std::min(edge.y, H - 0.002f));
    float pos, dir;
    c.pdfWe(c.generateRay(inside.x, inside.y, W, H).d, W, H, tanHalf, &pos, &dir);
    REQUIRE(dir > 0);
    CHECK(c.generatedPdfDir(d, W, H, tanHalf) == Approx(dir).epsilon(1e-4));
    const float cosTheta = glm::dot(d, c.forward);
    CHECK(c.generatedPdfDir(d, W, H, tanHalf) == Approx(1.0 / (c.filmArea(W, H) * std::pow(cosTheta, 3))).epsilon(1e-5));
  }
}

TEST_CASE("light emission densities: sampleLe's pdfs are pdfLe's - integrate to 1 - and the flux is Le cos/(pdfPos pdfDir)") {
  // The densities bidirectional methods weigh strategies with must be those sampleLe draws
  // from: each light's emitted rays carry pdfs equal to pdfLe() of the same ray, and pdfDir
  // integrates to 1 over the sphere (uniform sphere estimate, σ ≈ a few 0.1%).
  std::vector<std::unique_ptr<Light>> lights;
  lights.push_back(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(2.0f)));
  lights.push_back(std::make_unique<SpotLight>(Vec3(0, 1, 0), Vec3(0, -1, 0), Spectrum(5.0f), 0.3f, 0.6f));
  lights.push_back(std::make_unique<WarnSpotlight>(Vec3(0, 1, 0), Vec3(0, -1, 0), Spectrum(1.0f), 8.0f));
  lights.push_back(std::make_unique<AreaLight>(Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 1, 1), Spectrum(3.0f), false));
  lights.push_back(std::make_unique<AreaLight>(Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 1, 1), Spectrum(3.0f), true));
  auto directional = std::make_unique<DirectionalLight>(Vec3(0, -1, 0), Spectrum(1.0f));
  directional->preprocess(Vec3(0), 2.0f);
  lights.push_back(std::move(directional));
  Rng rng(5);
  for (auto& light : lights) {
    INFO(light->name());
    for (int i = 0; i < 200; ++i) {
      EmittedRay e = light->sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()),
                                     SampledWavelengths::rgb());
      float pos, dir;
      light->pdfLe(e.ray, e.n, &pos, &dir);
      CHECK(pos == Approx(e.pdfPos).epsilon(1e-4));
      CHECK(dir == Approx(e.pdfDir).epsilon(1e-4));
      if (!light->isDelta()) {  // area lights: flux = Le |cosθ| / (pdfPos pdfDir)
        Spectrum Le = light->L(e.ray.o, e.ray.d, SampledWavelengths::rgb());
        CHECK(e.flux.g == Approx(Le.g * std::abs(glm::dot(e.n, e.ray.d)) / (e.pdfPos * e.pdfDir)).epsilon(1e-4));
      }
    }
    if (light->isDeltaDirection()) continue;  // a delta in direction: nothing to integrate
    // σ of the estimate: √(4π∫pdf² dω − 1)/√N, 0.25% for the 1.1 sr spot cone, 0.2% for the
    // Warn lobe (s = 8) at N = 2·10⁶: 1% is four σ.
    const int N = 2000000;
    double sum = 0;
    Ray probe;
    for (int i = 0; i < N; ++i) {
      probe.d = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
      float pos, dir;
      light->pdfLe(probe, Vec3(0), &pos, &dir);
      sum += dir * 4 * kPi;
    }
    CHECK(sum / N == Approx(1.0).epsilon(0.01));
  }
}
