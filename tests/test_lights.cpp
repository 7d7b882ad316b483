// Light normalisations: ∫ I dω = Φ by numerical integration; the emitted photons' flux averages
// to Φ; emitted directions follow I(ω) (chi-square on a histogram); area lights: Φ = πLA and
// irradiance against Lambert's closed form for polygons.
#include <catch2/catch.hpp>

#include "core/rng.h"
#include "lights/area_light.h"
#include "lights/directional_light.h"
#include "lights/environment_light.h"
#include "lights/point_light.h"
#include "lights/spot_light.h"
#include "lights/warn_spotlight.h"
#include "stats.h"

using namespace pl;

namespace {

// ∫ I(ω) dω over the sphere, with I read back through sampleLi: at distance r in direction ω
// from the light, Li·r² = I(ω). Midpoint rule in (cosθ, φ) around the light's axis −... any axis.
double integrateIntensity(const Light& light, const Vec3& position) {
  const int nCos = 2000, nPhi = 64;
  const float r = 3.0f;
  double sum = 0;
  for (int i = 0; i < nCos; ++i)
    for (int j = 0; j < nPhi; ++j) {
      float c = -1 + 2 * (i + 0.5f) / nCos, phi = 2 * kPi * (j + 0.5f) / nPhi, s = std::sqrt(1 - c * c);
      Vec3 w(s * std::cos(phi), c, s * std::sin(phi));
      LightSample ls;
      if (light.sampleLi(position + r * w, Vec2(0.5f), SampledWavelengths::rgb(), &ls)) sum += ls.Li.g * r * r;
    }
  return sum * (2.0 / nCos) * (2 * kPi / nPhi);
}

double meanEmittedFlux(const Light& light, int N) {
  Rng rng(11, 0);
  double sum = 0;
  for (int i = 0; i < N; ++i)
    sum += light.sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()), SampledWavelengths::rgb()).flux.g;
  return sum / N;
}

// Histogram of cosθ (angle to `axis`) of emitted rays, each weighted by its flux, against the
// expected share of power per bin, ∫ I dω over the bin / Φ.
double emittedDirectionPValue(const Light& light, const Vec3& position, const Vec3& axis) {
  const int bins = 40, N = 200000;
  std::vector<double> observed(bins, 0), expected(bins, 0);
  Rng rng(12, 0);
  double total = 0;
  for (int i = 0; i < N; ++i) {
    EmittedRay e = light.sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()), SampledWavelengths::rgb());
    float c = glm::dot(e.ray.d, axis);
    int b = std::min(bins - 1, int((c + 1) / 2 * bins));
    // Photons of unequal flux: count each in proportion to its flux (mean flux normalises).
    observed[b] += e.flux.g;
    total += e.flux.g;
  }
  for (auto& o : observed) o *= N / total;
  for (int b = 0; b < bins; ++b) {
    const int sub = 200;
    double sum = 0;
    for (int k = 0; k < sub; ++k) {
      float c = -1 + 2 * (b + (k + 0.5f) / sub) / bins;
      float s = std::sqrt(1 - c * c);
      LightSample ls;
      Vec3 w = c * axis + s * glm::normalize(glm::cross(axis, Vec3(0.3f, 0.1f, 0.9f)));
      if (light.sampleLi(position + 2.0f * w, Vec2(0.5f), SampledWavelengths::rgb(), &ls)) sum += ls.Li.g * 4.0f * 2 * kPi;
    }
    expected[b] = N * (sum / sub) * (2.0 / bins) / light.power().g;
  }
  return test::chiSquarePValue(observed, expected);
}

}  // namespace

TEST_CASE("isotropic point light: I = Φ/4π - ∫ I dω = Φ - photons carry Φ each - uniformly") {
  Vec3 p(0.5f, 1.0f, -0.2f);
  PointLight light(p, PointLight::intensityForPower(Spectrum(100.0f)));
  CHECK(light.power().g == Approx(100.0f));
  CHECK(integrateIntensity(light, p) == Approx(100.0).epsilon(1e-3));
  LightSample ls;
  REQUIRE(light.sampleLi(p + Vec3(0, -2, 0), Vec2(0.5f), SampledWavelengths::rgb(), &ls));
  CHECK(ls.Li.g == Approx(100.0f / (4 * kPi) / 4.0f));  // I / r²
  CHECK(meanEmittedFlux(light, 1000) == Approx(100.0));
  CHECK(emittedDirectionPValue(light, p, Vec3(0, 1, 0)) > 1e-3);
}

TEST_CASE("glTF spot light: the spec's falloff integrates to the reported power") {
  Vec3 p(0, 2, 0), down(0, -1, 0);
  SpotLight light(p, down, Spectrum(10.0f), 0.3f, 0.6f);
  float ci = std::cos(0.3f), co = std::cos(0.6f);
  double expected = 10.0 * 2 * kPi * ((1 - ci) + (ci - co) / 3);
  CHECK(light.power().g == Approx(expected).epsilon(1e-5));
  CHECK(integrateIntensity(light, p) == Approx(expected).epsilon(2e-3));
  CHECK(meanEmittedFlux(light, 400000) == Approx(expected).epsilon(5e-3));
  CHECK(emittedDirectionPValue(light, p, down) > 1e-3);
  // `power` sets the intensity so that Φ is exact.
  SpotLight byPower(p, down, SpotLight::intensityForPower(Spectrum(42.0f), 0.3f, 0.6f), 0.3f, 0.6f);
  CHECK(byPower.power().g == Approx(42.0f));
  // Full intensity inside the inner cone, none outside the outer cone.
  CHECK(light.falloff(std::cos(0.2f)) == 1.0f);
  CHECK(light.falloff(std::cos(0.7f)) == 0.0f);
}

TEST_CASE("Warn spotlight: I(θ) = c cosˢθ with c = (s+1)Φ/2π integrates to Φ") {
  Vec3 p(0, 2, 0), down(0, -1, 0);
  for (float s : {1.0f, 8.0f, 50.0f}) {
    WarnSpotlight light(p, down, WarnSpotlight::cForPower(Spectrum(30.0f), s), s);
    INFO("s=" << s);
    CHECK(light.power().g == Approx(30.0f));
    CHECK(light.intensity(1.0f).g == Approx((s + 1) * 30.0f / (2 * kPi)));
    CHECK(integrateIntensity(light, p) == Approx(30.0).epsilon(3e-3));
    CHECK(meanEmittedFlux(light, 1000) == Approx(30.0));
    CHECK(emittedDirectionPValue(light, p, down) > 1e-3);
  }
}

TEST_CASE("area light: Φ = π·L·A - photons' mean flux is Φ - directions cosine-distributed") {
  Vec3 a(0, 1, 0), b(1, 1, 0), c(0, 1, 1);  // area 1/2; counter-clockwise seen from below
  AreaLight one(a, b, c, Spectrum(3.0f), false);
  CHECK(one.normal().y == Approx(-1.0f));
  CHECK(one.area() == Approx(0.5f));
  CHECK(one.power().g == Approx(kPi * 3.0f * 0.5f));
  CHECK(meanEmittedFlux(one, 1000) == Approx(kPi * 1.5));
  AreaLight two(a, b, c, Spectrum(3.0f), true);
  CHECK(two.power().g == Approx(2 * kPi * 1.5f));
  CHECK(meanEmittedFlux(two, 1000) == Approx(2 * kPi * 1.5));
  // Emitted directions: cosine lobe about the normal, i.e. P(cosθ < μ) = μ².
  Rng rng(2, 2);
  std::vector<double> obs(10, 0), exp(10, 0);
  for (int i = 0; i < 100000; ++i) {
    EmittedRay e = one.sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()), SampledWavelengths::rgb());
    float cosTheta = glm::dot(e.ray.d, one.normal());
    REQUIRE(cosTheta >= 0.0f);
    obs[std::min(9, int(cosTheta * 10))] += 1;
  }
  for (int k = 0; k < 10; ++k) exp[k] = 100000 * (std::pow((k + 1) / 10.0, 2) - std::pow(k / 10.0, 2));
  CHECK(test::chiSquarePValue(obs, exp) > 1e-3);
  // One-sided: nothing is emitted from the back.
  CHECK(one.L(Vec2(0.0f), Vec3(0, 1, 0), SampledWavelengths::rgb()).g == 0.0f);
  CHECK(two.L(Vec2(0.0f), Vec3(0, 1, 0), SampledWavelengths::rgb()).g == 3.0f);
}

TEST_CASE("area light sampling reproduces Lambert's irradiance formula for a polygon") {
  // E at x = (L/2) Σ_edges β_i (n · unit(u_i × u_{i+1})), u_i unit vectors towards the vertices.
  Vec3 v[4] = {{-0.3f, 1, -0.2f}, {0.5f, 1, -0.2f}, {0.5f, 1, 0.4f}, {-0.3f, 1, 0.4f}};  // faces down
  AreaLight t0(v[0], v[1], v[2], Spectrum(2.0f), false), t1(v[0], v[2], v[3], Spectrum(2.0f), false);
  for (Vec3 x : {Vec3(0, 0, 0), Vec3(0.7f, 0.2f, -0.5f)}) {
    Vec3 n(0, 1, 0);
    double lambert = 0;
    for (int i = 0; i < 4; ++i) {
      Vec3 ui = glm::normalize(v[i] - x), uj = glm::normalize(v[(i + 1) % 4] - x);
      lambert += std::acos(glm::dot(ui, uj)) * glm::dot(n, glm::normalize(glm::cross(ui, uj)));
    }
    lambert = std::abs(lambert) * 2.0 / 2.0;  // L = 2
    Rng rng(8, 8);
    double sum = 0;
    const int N = 200000;
    for (int i = 0; i < N; ++i) {
      const AreaLight& t = i % 2 ? t1 : t0;  // both halves, half the samples each
      LightSample ls;
      if (t.sampleLi(x, Vec2(rng.uniform(), rng.uniform()), SampledWavelengths::rgb(), &ls)) sum += 2.0 * ls.Li.g * glm::dot(ls.wi, n) / ls.pdf;
    }
    CHECK(sum / N == Approx(lambert).epsilon(5e-3));
  }
}

TEST_CASE("directional light: irradiance E - power through the scene's disc") {
  DirectionalLight light(Vec3(0, -1, 0), Spectrum(5.0f));
  light.preprocess(Vec3(0), 2.0f);
  CHECK(light.power().g == Approx(5.0f * kPi * 4.0f));
  CHECK(meanEmittedFlux(light, 100) == Approx(5.0 * kPi * 4.0));
  DirectionalLight byPower(Vec3(0, -1, 0), Spectrum(1.0f), 10.0f);
  byPower.preprocess(Vec3(0), 2.0f);
  CHECK(byPower.power().g == Approx(10.0f));
}

TEST_CASE("light types: what each light says it is, its emission and its densities show") {
  auto env = EnvironmentLight::constant(Spectrum(0.5f));
  env->preprocess(Vec3(0), 2.0f);
  DirectionalLight sun(Vec3(0, -1, 0), Spectrum(5.0f));
  sun.preprocess(Vec3(0), 2.0f);
  PointLight point(Vec3(0, 2, 0), Spectrum(3.0f));
  SpotLight spot(Vec3(0, 2, 0), Vec3(0, -1, 0), Spectrum(3.0f), 0.3f, 0.6f);
  WarnSpotlight warn(Vec3(0, 2, 0), Vec3(0, -1, 0), Spectrum(1.0f), 4.0f);
  AreaLight area(Vec3(-1, 2, -1), Vec3(1, 2, -1), Vec3(-1, 2, 1), Spectrum(2.0f), false);
  const std::vector<std::pair<const Light*, LightType>> lights = {
      {env.get(), LightType::kInfinite},   {&sun, LightType::kDeltaDirection}, {&point, LightType::kDeltaPosition},
      {&spot, LightType::kDeltaPosition}, {&warn, LightType::kDeltaPosition}, {&area, LightType::kArea}};
  Rng rng(5, 5);
  for (const auto& [light, type] : lights) {
    INFO(light->name());
    REQUIRE(light->type() == type);
    // Emitted rays: one origin for a delta position, one direction for a delta direction, origins
    // and directions with densities otherwise.
    Vec3 origin0(0.0f), direction0(0.0f);
    bool oneOrigin = true, oneDirection = true;
    for (int i = 0; i < 64; ++i) {
      const EmittedRay e = light->sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()), SampledWavelengths::rgb());
      if (i == 0) origin0 = e.ray.o, direction0 = e.ray.d;
      oneOrigin &= glm::length(e.ray.o - origin0) < 1e-5f;
      oneDirection &= glm::length(e.ray.d - direction0) < 1e-5f;
    }
    CHECK(oneOrigin == (type == LightType::kDeltaPosition));
    CHECK(oneDirection == (type == LightType::kDeltaDirection));
    // A ray can find it (radiance L > 0 and a solid-angle density) only where it is not a delta.
    LightSample ls;
    const Vec3 p(0.2f, 0.0f, 0.1f);
    REQUIRE(light->sampleLi(p, Vec2(0.3f, 0.6f), SampledWavelengths::rgb(), &ls));
    const Vec3 y = p + ls.wi * std::min(ls.distance, 10.0f);
    const bool found = light->pdfLi(p, y) > 0 && maxComponent(light->L(y, -ls.wi, SampledWavelengths::rgb())) > 0;
    CHECK(found == !light->isDelta());
    CHECK(std::isinf(ls.distance) == (type == LightType::kInfinite || type == LightType::kDeltaDirection));
  }
}
