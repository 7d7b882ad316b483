// Spectral mode: the CIE tables and conversions, the RGB uplift, Planck's law, the film's
// wavelength estimator, dispersion (Cauchy, Snell per wavelength, the prism's minimum
// deviation), and agreement with RGB mode on grey scenes.
#include <catch2/catch.hpp>

#include "bsdfs/dielectric.h"
#include "render/integrator.h"
#include "lights/point_light.h"
#include "integrators/progressive.h"
#include "render/renderer.h"
#include "gltf_fixture.h"
#include "scene/gltf_loader.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"
#include "spectral/spectral.h"

using namespace pl;
using namespace pl::test;

TEST_CASE("spectral: the CIE tables - normalisation - equal energy - D65 white - matrix round trip") {
  double X = 0, Y = 0, Z = 0;
  for (int i = 0; i < kCieSamples; ++i) X += kCieX[i], Y += kCieY[i], Z += kCieZ[i];
  CHECK(Y == Approx(106.857).epsilon(1e-4));  // CIE: ∫ȳ dλ = 106.857 (1 nm sum, 360–830 nm)
  CHECK(Y == Approx(kCieYIntegral).epsilon(1e-6));
  // The equal-energy spectrum E has chromaticity x = y = 1/3.
  CHECK(X / (X + Y + Z) == Approx(1.0 / 3).margin(1e-3));
  CHECK(Y / (X + Y + Z) == Approx(1.0 / 3).margin(1e-3));
  // D65, normalised to Y = 1, is sRGB white (1, 1, 1) through the standard matrix alone.
  double dx = 0, dy = 0, dz = 0;
  for (int i = 0; i < kCieSamples; ++i) dx += kD65[i] * kCieX[i], dy += kD65[i] * kCieY[i], dz += kD65[i] * kCieZ[i];
  Vec3 white = XYZToRGB(Vec3(float(dx / dy), 1.0f, float(dz / dy)));
  CHECK(white.x == Approx(1.0f).margin(1e-3));
  CHECK(white.y == Approx(1.0f).margin(1e-3));
  CHECK(white.z == Approx(1.0f).margin(1e-3));
  CHECK(dx / (dx + dy + dz) == Approx(0.31272).margin(2e-4));  // D65's chromaticity
  Rng rng(7);
  for (int i = 0; i < 100; ++i) {
    Vec3 c(rng.uniform() * 2 - 0.5f, rng.uniform() * 2 - 0.5f, rng.uniform() * 2 - 0.5f);
    Vec3 back = XYZToRGB(RGBToXYZ(c));
    for (int k = 0; k < 3; ++k) CHECK(back[k] == Approx(c[k]).margin(1e-6));
  }
}

TEST_CASE("spectral: the RGB uplift returns the same RGB over the whole gamut - reflectances in [0 1]") {
  const RGBUplift& u = RGBUplift::instance();
  CHECK(u.nodeError() < 1e-5f);
  const int n = 11;  // a grid that misses most of the uplift's own 9³ nodes
  float worst = 0, lo = 1, hi = 0;
  std::vector<float> s(kCieSamples);
  for (int r = 0; r < n; ++r)
    for (int g = 0; g < n; ++g)
      for (int b = 0; b < n; ++b) {
        Vec3 rgb = Vec3(r, g, b) / float(n - 1);
        for (int i = 0; i < kCieSamples; ++i) {
          s[i] = u.reflectance(rgb, kLambdaMin + i);
          lo = std::min(lo, s[i]);
          hi = std::max(hi, s[i]);
        }
        Vec3 e = glm::abs(u.rgbOfReflectance(s) - rgb);
        worst = std::max(worst, std::max(e.x, std::max(e.y, e.z)));
      }
  INFO("worst round-trip error " << worst);
  CHECK(worst < 1e-4f);  // the stated tolerance (docs: how-to/spectral.md)
  CHECK(lo >= 0.0f);
  CHECK(hi <= 1.0f);
  // Greys are flat spectra.
  for (float lambda : {400.0f, 550.0f, 700.0f}) CHECK(u.reflectance(Vec3(0.3f), lambda) == Approx(0.3f).epsilon(1e-6));
}

TEST_CASE("spectral: the film's wavelength estimator is unbiased - emission round trips to its RGB") {
  // Stratified λ over the whole range: the average of the film's estimate is the integral.
  for (Vec3 rgb : {Vec3(1, 1, 1), Vec3(0.9f, 0.2f, 0.05f), Vec3(0.1f, 0.5f, 2.0f)}) {
    Vec3 sum(0.0f);
    const int N = 20000;
    for (int i = 0; i < N; ++i) {
      SampledWavelengths ctx = SampledWavelengths::sample((i + 0.5f) / N);
      sum += spectralToRGB(spectralEmission(rgb, ctx), ctx.lambda);
    }
    Vec3 mean = sum / float(N);
    INFO(rgb.x << " " << rgb.y << " " << rgb.z);
    for (int k = 0; k < 3; ++k) CHECK(mean[k] == Approx(rgb[k]).margin(2e-3 * std::max(1.0f, rgb[k])));
  }
  // The three wavelengths are a stratified rotation: each uniform, a third of the range apart.
  Vec3 l = sampleWavelengths(0.9f);
  CHECK(l.x == Approx(kLambdaMin + 0.9f * 470));
  CHECK(l.y == Approx(kLambdaMin + (0.9f + 1.0f / 3 - 1) * 470));
  CHECK(l.z == Approx(kLambdaMin + (0.9f + 2.0f / 3 - 1) * 470));
}

TEST_CASE("spectral: the illuminants as emitters - D65 is white - E and a blackbody keep their luminance") {
  // Through the film, each emitter's spectrum gives back the sRGB colour RGB mode uses.
  const int N = 20000;
  LazySpectrum::Table E, B;
  equalEnergyTable(&E);
  blackbodyTable(3200, &B);
  Vec3 e(0.0f), bb(0.0f);
  for (int i = 0; i < N; ++i) {
    SampledWavelengths ctx = SampledWavelengths::sample((i + 0.5f) / N);
    e += spectralToRGB(LazySpectrum::at(E, ctx.lambda), ctx.lambda);
    bb += spectralToRGB(LazySpectrum::at(B, ctx.lambda), ctx.lambda);
  }
  e /= float(N);
  bb /= float(N);
  Vec3 eRGB = equalEnergyRGB(), bbRGB = blackbodyRGB(3200);
  for (int k = 0; k < 3; ++k) {
    CHECK(e[k] == Approx(eRGB[k]).epsilon(2e-3));
    CHECK(bb[k] == Approx(bbRGB[k]).epsilon(2e-3));
  }
  CHECK(0.2126f * eRGB.x + 0.7152f * eRGB.y + 0.0722f * eRGB.z == Approx(1.0f).epsilon(1e-3));
  CHECK(eRGB.x > eRGB.z);  // E is pinker than D65's white
}

TEST_CASE("spectral: Planck's law - Wien's displacement - the blackbody's colour") {
  for (double T : {3000.0, 5000.0, 6500.0}) {
    double best = 0, peak = 0;
    for (double l = 200; l < 3000; l += 0.25) {
      double b = planck(l, T);
      if (b > best) best = b, peak = l;
    }
    CHECK(peak * T == Approx(2.897771955e6).epsilon(1e-3));  // Wien: λ_max T = b
  }
  // Stefan–Boltzmann: π ∫ B dλ = σ T⁴.
  double T = 5000, sum = 0;
  for (double l = 10; l < 100000; l += 1) sum += planck(l, T) * 1e-9;
  CHECK(kPi * sum == Approx(5.670374419e-8 * T * T * T * T).epsilon(2e-3));
  // A 6504 K blackbody is near white; a 2700 K one is reddish; both have luminance 1.
  Vec3 w = blackbodyRGB(6504), warm = blackbodyRGB(2700);
  CHECK(w.x == Approx(1.0f).margin(0.06f));
  CHECK(w.z == Approx(1.0f).margin(0.12f));
  CHECK(warm.x > warm.y);
  CHECK(warm.y > warm.z);
  CHECK(0.2126f * warm.x + 0.7152f * warm.y + 0.0722f * warm.z == Approx(1.0f).epsilon(1e-3));
}

TEST_CASE("spectral: Cauchy's index from n_d and the Abbe number - Snell's law per wavelength") {
  Dielectric glass(1.6f, 20.0f);
  CHECK(glass.eta(587.56f) == Approx(1.6f).epsilon(1e-6));
  CHECK((glass.eta(587.56f) - 1) / (glass.eta(486.13f) - glass.eta(656.27f)) == Approx(20.0f).epsilon(1e-4));
  CHECK(glass.eta(400.0f) > glass.eta(700.0f));  // normal dispersion: blue bends more
  for (float lambda : {420.0f, 550.0f, 680.0f}) {
    SampledWavelengths ctx;
    ctx.spectral = true;
    ctx.lambda = Vec3(lambda, 500.0f, 600.0f);
    float thetaI = 0.6f;
    Vec3 wo(std::sin(thetaI), 0.0f, std::cos(thetaI));
    BSDFSample s;
    REQUIRE(glass.sample(wo, BSDFContext(Vec2(0), ctx, TransportMode::Importance), Vec2(0), 0.9999f, &s));  // uc ≥ F: refraction
    float sinT = std::sqrt(s.wi.x * s.wi.x + s.wi.y * s.wi.y);
    CHECK(std::sin(thetaI) == Approx(glass.eta(lambda) * sinT).epsilon(1e-5));  // Snell at the hero λ
    CHECK(s.weight.x == Approx(3.0f));  // the hero carries the three wavelengths' share
    CHECK(s.weight.y == 0.0f);
    CHECK(s.terminatesSecondary);  // the caller's path follows the hero alone from here on
    ctx.terminateSecondary();
    BSDFSample again;  // a second dispersive interface does not scale again
    REQUIRE(glass.sample(-s.wi, BSDFContext(Vec2(0), ctx, TransportMode::Importance), Vec2(0), 0.9999f, &again));
    CHECK(again.weight.x == Approx(1.0f));
  }
  // RGB mode: no dispersion, no hero.
  BSDFSample s;
  REQUIRE(glass.sample(Vec3(0.5f, 0, std::sqrt(0.75f)), BSDFContext(Vec2(0), SampledWavelengths::rgb(), TransportMode::Importance), Vec2(0), 0.9999f, &s));
  CHECK(s.weight.x == Approx(1.0f));
  CHECK(s.weight.y == Approx(1.0f));
}

TEST_CASE("spectral: a ray through the prism at minimum deviation turns by 2 asin(n sin(A/2)) - A per wavelength") {
  // The shipped prism's glass (n_d = 1.6, V_d = 20), apex A = 60°, axis along z, traced through
  // the scene: Embree hits, the dielectric's refraction, out the other face.
  const float A = kPi / 3, s = 0.6f, y0 = 0.0f, h = s * std::sqrt(3.0f) / 2;
  Scene scene;
  uint32_t glass = scene.addMaterial({"glass", std::make_unique<Dielectric>(1.6f, 20.0f), Spectrum(0), false});
  Vec3 a(-s / 2, y0, 0), b(s / 2, y0, 0), c(0, y0 + h, 0), dz(0, 0, 1);
  std::vector<Vec3> p = {a + dz, b + dz, c + dz, a - dz, b - dz, c - dz};
  scene.addMesh(p, {}, {}, {0, 1, 2, 3, 5, 4, 0, 2, 5, 0, 5, 3, 1, 4, 5, 1, 5, 2, 0, 3, 4, 0, 4, 1}, glass);
  scene.addLight(std::make_unique<PointLight>(Vec3(0, 5, 0), Spectrum(1.0f)));
  scene.setCamera(lookingDown(3.0f));
  scene.commit();
  for (float lambda : {430.0f, 550.0f, 650.0f}) {
    float n = Dielectric(1.6f, 20.0f).eta(lambda);
    float deltaMin = 2 * std::asin(n * std::sin(A / 2)) - A;
    // Incidence (δ_min + A)/2 on the left face, whose inward normal points along −30°.
    float incidence = (deltaMin + A) / 2, heading = -kPi / 6 + incidence;
    Vec3 d(std::cos(heading), std::sin(heading), 0.0f);
    Vec3 target = (a + c) * 0.5f;
    Ray ray{target - 2.0f * d, d};
    SampledWavelengths ctx;
    ctx.spectral = true;
    ctx.lambda = Vec3(lambda, 500, 600);
    for (int bounce = 0; bounce < 2; ++bounce) {
      SurfaceHit hit;
      REQUIRE(scene.intersect(ray, &hit));
      BSDFSample bs;
      REQUIRE(hit.bsdf->sample(hit.shading.toLocal(-ray.d), BSDFContext(hit.uv, ctx, TransportMode::Importance), Vec2(0), 0.99999f, &bs));
      if (bs.terminatesSecondary) ctx.terminateSecondary();
      ray = scene.spawnRay(hit, hit.shading.toWorld(bs.wi));
    }
    float deviation = std::acos(glm::clamp(glm::dot(d, ray.d), -1.0f, 1.0f));
    INFO("λ = " << lambda << " nm, n = " << n);
    CHECK(deviation == Approx(deltaMin).epsilon(1e-4));
    CHECK(std::abs(ray.d.y) == Approx(std::abs(d.y)).epsilon(1e-4));  // symmetric exit at minimum deviation
  }
}

TEST_CASE("spectral: spectral and RGB mode agree on grey scenes - point light over a plane - furnace") {
  // Point light of intensity I at height h over a grey floor: L = ρ/π · I cosθ / r².
  Scene scene;
  float rho = 0.5f, h = 1.0f, I = 2.0f;
  addQuad(scene, {-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, lambertian(scene, rho));
  scene.addLight(std::make_unique<PointLight>(Vec3(0, h, 0), Spectrum(I)));
  scene.setCamera(lookingDown(2.0f, 1.0f));
  scene.commit();
  // Three wavelengths per sample make colour noise (x̄, ȳ, z̄ weigh them unevenly): 65 k samples
  // put the mean within ~0.5% (1σ) of its expectation.
  const int W = 16;
  RenderOptions o;
  o.width = o.height = W;
  o.spp = 256;
  o.spectral = true;
  ImageRGB expected = expectedFloorImage(scene, W, W, [&](const Vec3& x) {
    Vec3 d = Vec3(0, h, 0) - x;
    float r2 = glm::dot(d, d);
    return rho / kPi * I * (h / std::sqrt(r2)) / r2;
  });
  auto checkGrey = [&](const char* name, const ImageRGB& img) {
    INFO(name);
    double ref = 0;
    for (int i = 0; i < W * W; ++i) ref += expected.data[3 * i];
    for (int k = 0; k < 3; ++k) {  // each channel: grey stays grey, and as bright as in closed form
      double sum = 0;
      for (int i = 0; i < W * W; ++i) sum += img.data[3 * i + k];
      CHECK(sum / ref == Approx(1.0).epsilon(0.015));
    }
  };
  for (const char* name : {"direct", "path"}) {
    auto integrator = makeWith(name, {}, o);
    ImageRGB img = render(scene, *integrator, o, nullptr);
    checkGrey(name, img);
  }
  // The progressive methods: the same (the floor's photons are direct ones, which SPPM and PPPM
  // leave to shadow rays), with one wavelength triple per pixel and pass.
  for (const char* name : {"sppm", "pppm"}) {
    RenderInfo info;
    checkGrey(name, makeWith(name, {{"passes", 256}, {"photons_per_pass", 1000}}, o)->render(scene, o, &info));
  }

  // The closed furnace: L = Le/(1 − ρ) = 2, with the path tracer and with photon mapping.
  Scene furnace;
  uint32_t m = furnace.addMaterial({"furnace", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.5f))), Spectrum(1.0f), true});
  float s = 1.0f;
  addQuad(furnace, {-s, -s, -s}, {s, -s, -s}, {s, -s, s}, {-s, -s, s}, m);
  addQuad(furnace, {-s, s, -s}, {-s, s, s}, {s, s, s}, {s, s, -s}, m);
  addQuad(furnace, {-s, -s, -s}, {-s, -s, s}, {-s, s, s}, {-s, s, -s}, m);
  addQuad(furnace, {s, -s, -s}, {s, s, -s}, {s, s, s}, {s, -s, s}, m);
  addQuad(furnace, {-s, -s, -s}, {-s, s, -s}, {s, s, -s}, {s, -s, -s}, m);
  addQuad(furnace, {-s, -s, s}, {s, -s, s}, {s, s, s}, {-s, s, s}, m);
  Camera cam;
  cam.position = Vec3(0.0f);
  cam.forward = Vec3(0, 0, -1);
  cam.up = Vec3(0, 1, 0);
  cam.right = Vec3(1, 0, 0);
  cam.yfov = 1.0f;
  furnace.setCamera(cam);
  furnace.commit();
  o.width = o.height = 16;
  o.spp = 16;
  for (const char* name : {"path", "photon"}) {
    auto integrator = makeWith(name, {{"photons", 200000}, {"caustic_photons", 0}, {"final_gather", 16}}, o);
    ImageRGB img = render(furnace, *integrator, o, nullptr);
    double mean = 0;
    for (float v : img.data) mean += v;
    mean /= img.data.size();
    INFO(name);
    CHECK(mean == Approx(2.0).epsilon(0.04));  // 4 k samples: ~1.5% colour noise (1σ)
  }
}

TEST_CASE("spectral: the loader reads temperature - illuminant - KHR_materials_dispersion") {
  GltfFixture f;
  f.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"temperature", 2700}}}};
  f.doc["materials"][0]["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                         {"KHR_materials_volume", {{"thicknessFactor", 1.0}}},
                                         {"KHR_materials_ior", {{"ior", 1.6}}},
                                         {"KHR_materials_dispersion", {{"dispersion", 1.0}}}};
  auto scene = loadGltf(f.write("spectral-extras.gltf"));
  REQUIRE(scene->lights().size() == 1);
  CHECK(scene->lights()[0]->temperature == 2700.0f);
  Spectrum power = scene->lights()[0]->power();
  Vec3 bb = blackbodyRGB(2700);
  CHECK(power.x / power.z == Approx(bb.x / bb.z).epsilon(1e-4));  // the blackbody's colour in RGB mode
  SurfaceHit hit;
  REQUIRE(scene->intersect(Ray{Vec3(0, 1, 0), Vec3(0, -1, 0)}, &hit));
  auto* glass = dynamic_cast<const Dielectric*>(hit.bsdf);
  REQUIRE(glass);
  CHECK(glass->abbe() == Approx(20.0f));  // dispersion = 20/V_d

  auto error = [](GltfFixture& g, const char* name) {
    try {
      loadGltf(g.write(name));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  GltfFixture cold;
  cold.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"temperature", 50}}}};
  CHECK_THAT(error(cold, "cold.gltf"), Catch::Matchers::Contains("extras.photonlab.temperature: must be a temperature in kelvin"));
  GltfFixture bad;
  bad.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"illuminant", "A"}}}};
  CHECK_THAT(error(bad, "illuminant.gltf"), Catch::Matchers::Contains("extras.photonlab.illuminant: must be"));
  GltfFixture e;
  e.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"illuminant", "E"}}}};
  auto es = loadGltf(e.write("illuminant-e.gltf"));
  CHECK(es->lights()[0]->equalEnergy);
}
