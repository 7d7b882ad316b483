// Every light through every path that carries its light, against closed forms, per point and
// per pixel (a right mean can hide a wrong level with salt noise around it):
//   - photons alone: the photon map's direct photons at points of a floor, and PPM images (all
//     light from photons), so emission sampling (Light::sampleLe) is tested without shadow rays;
//   - shadow rays alone: the direct-lighting integrator (Light::sampleLi);
//   - light tracing alone: paths from Light::sampleLe splatted to the camera (Camera::sampleWi).
// The scene is a 4 m diffuse floor (ρ = 0.8) under one light; with nothing else to bounce off,
// the floor's radiance is exactly L = ρ/π · E(x), E from the light's closed form.
#include <catch2/catch.hpp>

#include <algorithm>

#include "bsdfs/dielectric.h"
#include "bsdfs/metallic_roughness.h"
#include "bsdfs/thin_dielectric.h"
#include "ggx_reference.h"
#include "lights/directional_light.h"
#include "lights/environment_light.h"
#include "lights/spot_light.h"
#include "lights/warn_spotlight.h"
#include "photon/photon_tracer.h"
#include "radiosity/patch_mesh.h"
#include "integrators/progressive.h"
#include "render/renderer.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

constexpr float kRho = 0.8f, kHalf = 2.0f;  // floor albedo, half its side (m)

struct LightCase {
  const char* name;
  std::function<void(Scene&)> add;      // adds the light (and, for area lights, its geometry)
  std::function<double(const Vec3&)> E;  // closed-form irradiance on the floor (y = 0, normal +y)
  bool environment = false;             // a sky (radiosity refuses one)
  // Samples per pixel relative to the other lights' in the tests whose acceptance is a median:
  // a sky's next-event estimate is 0 for the half of its directions below the horizon and its
  // light paths land anywhere on its 25 m² disc, so a pixel's estimate is skewed (its median
  // below its mean) until more samples average it.
  int effort = 1;
};

// The sky map of the environment case: 8×4 texels (row 0 at the zenith), grey levels that vary
// with both row and column, rotated 30° about +Y, so that its E tests rows, columns and the
// luminance-weighted sampling. The floor (normal +y) sees rows 0 and 1 (θ < π/2) with cos θ:
// texel (i, j) contributes L_ij ∫ cosθ dω = L_ij (2π/W) (cos²θ_j − cos²θ_{j+1})/2, whatever the
// rotation about the normal; rows 2 and 3 are below the horizon.
ImageRGB skyMap() {
  ImageRGB map(8, 4);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 8; ++i) map.set(i, j, Spectrum(0.3f + 0.25f * float((i * 3 + j * 5) % 7)));
  return map;
}
// The textured area light: a 0.6 m × 0.4 m emitter 1 m up, facing down, whose radiance is an
// 8×1 emissive texture [1 1 1 1 6 6 6 6] read bilinearly with repeat wrapping (glTF's default
// sampler), u running from 1/8 to 7/8 along x: Le = 1 on the left, 6 on the right, a linear
// ramp between the texel centres 3.5/8 and 4.5/8. Le(u) by that definition, and E(x) =
// ∫ Le cosθx cosθy / r² dA by the midpoint rule on 48 × 32 cells (Le is smooth but for the
// ramp's two kinks, and E varies slowly at 1 m: the rule is good to ~1e-4).
const float kTexels[8] = {1, 1, 1, 1, 6, 6, 6, 6};
double texturedLe(double u) {
  double x = u * 8 - 0.5, x0 = std::floor(x), f = x - x0;
  int i = (int(x0) % 8 + 8) % 8, j = (i + 1) % 8;
  return (1 - f) * kTexels[i] + f * kTexels[j];
}
double texturedE(const Vec3& x) {
  const int nx = 48, nz = 32;
  const double w = 0.6, d = 0.4, cell = w / nx * (d / nz);
  double E = 0;
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      const double px = -0.3 + (i + 0.5) * w / nx, pz = -0.2 + (k + 0.5) * d / nz;
      const double dx = px - x.x, dy = 1.0 - x.y, dz = pz - x.z, r2 = dx * dx + dy * dy + dz * dz;
      const double u = 0.125 + 0.75 * (px + 0.3) / w;
      E += texturedLe(u) * (dy * dy / r2) / r2 * cell;  // cosθx = cosθy = dy/r
    }
  return E;
}

double skyIrradiance(const ImageRGB& map) {
  double E = 0;
  for (int j = 0; j < map.height / 2; ++j) {
    double c0 = std::cos(kPi * j / map.height), c1 = std::cos(kPi * (j + 1) / map.height);
    for (int i = 0; i < map.width; ++i) E += map.at(i, j).g * (2 * kPi / map.width) * (c0 * c0 - c1 * c1) / 2;
  }
  return E;
}

// Lambert's formula for the irradiance from a polygon of uniform radiance L (vertices in order):
// E = (L/2) Σ_i β_i n·unit(u_i × u_{i+1}), β_i the angle between the unit vectors to vertices
// i and i+1. Independent of the renderer's sampling.
double lambertPolygon(const std::vector<Vec3>& v, const Vec3& x, const Vec3& n, double L) {
  double sum = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    glm::dvec3 a = glm::normalize(glm::dvec3(v[i] - x)), b = glm::normalize(glm::dvec3(v[(i + 1) % v.size()] - x));
    sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::dot(glm::dvec3(n), glm::normalize(glm::cross(a, b)));
  }
  return 0.5 * L * std::abs(sum);
}

std::vector<LightCase> lightCases() {
  const float h = 1.0f;  // punctual lights 1 m above the floor's centre, pointing down
  auto cosAt = [h](const Vec3& x) { return h / std::sqrt(double(h) * h + x.x * x.x + x.z * x.z); };
  auto r2At = [h](const Vec3& x) { return double(h) * h + x.x * x.x + x.z * x.z; };
  std::vector<LightCase> cases;
  // Isotropic point light: E = I cosθ / r².
  cases.push_back({"point", [](Scene& s) { s.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(3.0f))); },
                   [=](const Vec3& x) { return 3.0 * cosAt(x) / r2At(x); }});
  // glTF spot: I(θ) = I·a², a = clamp((cosθ − cos θo)/(cos θi − cos θo), 0, 1); here θ, the angle
  // off the axis, is also the angle of incidence.
  cases.push_back({"spot",
                   [](Scene& s) {
                     s.addLight(std::make_unique<SpotLight>(Vec3(0, 1, 0), Vec3(0, -1, 0), Spectrum(5.0f), 0.3f, 0.6f));
                   },
                   [=](const Vec3& x) {
                     double c = cosAt(x), ci = std::cos(0.3), co = std::cos(0.6);
                     double a = std::clamp((c - co) / (ci - co), 0.0, 1.0);
                     return 5.0 * a * a * c / r2At(x);
                   }});
  // Warn spotlight: I(θ) = c cosˢθ, c = (s + 1)Φ/2π.
  cases.push_back({"warn",
                   [](Scene& s) {
                     s.addLight(std::make_unique<WarnSpotlight>(Vec3(0, 1, 0), Vec3(0, -1, 0),
                                                                WarnSpotlight::cForPower(Spectrum(20.0f), 8.0f), 8.0f));
                   },
                   [=](const Vec3& x) {
                     double c = cosAt(x);
                     return (8.0 + 1) * 20.0 / (2 * kPi) * std::pow(c, 8.0) * c / r2At(x);
                   }});
  // Directional: E = 2 W/m² on a surface facing it, arriving 30° from the vertical: E cos 30°
  // on the floor (the case: photons came from a disc of radius R², 0.126 × this).
  cases.push_back({"directional",
                   [](Scene& s) {
                     float t = glm::radians(30.0f);
                     s.addLight(std::make_unique<DirectionalLight>(Vec3(std::sin(t), -std::cos(t), 0), Spectrum(2.0f)));
                   },
                   [](const Vec3&) { return 2.0 * std::cos(glm::radians(30.0)); }});
  // Area: a 0.6 m × 0.4 m one-sided emitter 1 m up, facing down, Le = 4 (Lambert's formula).
  const std::vector<Vec3> quad = {{-0.3f, 1, -0.2f}, {0.3f, 1, -0.2f}, {0.3f, 1, 0.2f}, {-0.3f, 1, 0.2f}};
  cases.push_back({"area",
                   [quad](Scene& s) {
                     // Black (ρ = 0): photons coming back from the floor end there.
                     uint32_t m = s.addMaterial({"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))),
                                                 Spectrum(4.0f), false});
                     // Counter-clockwise seen from below: the front face looks down at the floor.
                     addQuad(s, quad[0], quad[1], quad[2], quad[3], m);
                   },
                   [quad](const Vec3& x) { return lambertPolygon(quad, x, Vec3(0, 1, 0), 4.0); }});
  // Area with an emissive texture (texturedE): each point emits its texel's Le.
  cases.push_back({"area (textured)",
                   [quad](Scene& s) {
                     auto image = std::make_shared<Image>();
                     image->width = 8, image->height = 1;
                     for (float t : kTexels) image->texels.push_back(Spectrum(t));
                     Material m{"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(1.0f), false};
                     m.emissionTexture = std::make_shared<ColorTexture>(Spectrum(1.0f), image);
                     uint32_t id = s.addMaterial(std::move(m));
                     auto uvAt = [](const Vec3& p) { return Vec2(0.125f + 0.75f * (p.x + 0.3f) / 0.6f, 0.5f); };
                     s.addMesh({quad[0], quad[1], quad[2], quad[3]}, {}, {uvAt(quad[0]), uvAt(quad[1]), uvAt(quad[2]), uvAt(quad[3])},
                               {0, 1, 2, 0, 2, 3}, id);
                   },
                   [](const Vec3& x) { return texturedE(x); }});
  // Environment, constant: the open floor sees the whole upper hemisphere, E = π·L.
  cases.push_back({"environment (constant)", [](Scene& s) { s.addLight(EnvironmentLight::constant(Spectrum(0.7f))); },
                   [](const Vec3&) { return kPi * 0.7; }, true, 4});
  // Environment, a map (skyMap): E from its texels' cosine-weighted solid angles.
  cases.push_back({"environment (map)",
                   [](Scene& s) { s.addLight(std::make_unique<EnvironmentLight>(skyMap(), 30.0f, "test map")); },
                   [](const Vec3&) { return skyIrradiance(skyMap()); }, true, 4});
  return cases;
}

// Floor of side 2·half, the light, a camera 0.9 m up (below the area light) looking down at
// [−1.2, 1.2]².
std::unique_ptr<Scene> floorScene(const LightCase& c, float half = kHalf) {
  auto scene = std::make_unique<Scene>();
  addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, lambertian(*scene, kRho));
  c.add(*scene);
  scene->setCamera(lookingDown(0.9f, 2.0f * std::atan(1.2f / 0.9f)));
  scene->commit();
  return scene;
}

// What a fixed-radius uniform-kernel estimate at x converges to: E averaged over the disc of
// radius r around x, (1/πr²)∫ E dA, by the midpoint rule in polar coordinates.
double discAverage(const std::function<double(const Vec3&)>& E, const Vec3& x, float r) {
  const int nr = 24, nphi = 48;
  double sum = 0, weight = 0;
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < nphi; ++j) {
      double rho = r * (i + 0.5) / nr, phi = 2 * kPi * (j + 0.5) / nphi;
      sum += rho * E(x + Vec3(float(rho * std::cos(phi)), 0, float(rho * std::sin(phi))));
      weight += rho;
    }
  return sum / weight;
}

}  // namespace

TEST_CASE("photons alone: every light's direct photons reproduce its closed-form irradiance point by point", "[long]") {
  // 1M emitted paths; the global map's direct photons (L D) gathered with a fixed radius r and
  // the uniform kernel at a 17×17 grid of floor points (every 15 cm over [−1.2, 1.2]², so the
  // spot's falloff ring is crossed), wherever E is above a tenth of its maximum. The
  // estimate's expectation is the disc average of E (by quadrature here, so the kernel's blur
  // is accounted for), and its standard deviation σ² = Σ Φp²/(πr²)² comes from the photons
  // found (a compound Poisson count). Accepted: every |z| < 5.5 (≤ 289 points: a false alarm
  // has probability ~10⁻⁵ for normal errors; over seeds 7–11 the largest was 4.7); mean z² < 2 (expectation 1; with n ≥ 30 points P(> 2) < 10⁻³); and
  // |Σz/√n| < 4 (a standard normal), which catches a flux off by 2% (z ≈ 0.5 per point, so
  // Σz/√n ≈ 0.5√n ≥ 4 for n ≥ 64). A light whose photons leave from the wrong place fails by
  // many σ at once.
  const float r = 0.06f;
  for (const LightCase& c : lightCases()) {
    INFO(c.name);
    auto scene = floorScene(c);
    PhotonTracingOptions o;
    o.globalPaths = 1000000;
    o.causticPaths = 0;
    o.seed = 7;
    PhotonMaps maps = tracePhotons(*scene, o);
    std::vector<Neighbour> found;
    double maxE = 0;
    auto gridPoint = [](int i, int j) { return Vec3(-1.2f + 0.15f * i, 0, -1.2f + 0.15f * j); };
    for (int i = 0; i < 17; ++i)
      for (int j = 0; j < 17; ++j) maxE = std::max(maxE, c.E(gridPoint(i, j)));
    double maxZ = 0, sumZ2 = 0, sumZ = 0;
    int n = 0;
    for (int i = 0; i < 17; ++i)
      for (int j = 0; j < 17; ++j) {
        Vec3 x = gridPoint(i, j);
        double expected = discAverage(c.E, x, r);
        maps.global.withinRadius(x, Vec3(0, 1, 0), Photon::kAcceptDirect, r, &found);
        double sum = 0, sum2 = 0;
        for (const Neighbour& nb : found) {
          double phi = maps.global.flux(maps.global.photons()[nb.index]).g;
          sum += phi;
          sum2 += phi * phi;
        }
        const double area = kPi * r * r;
        if (expected < 1e-9) {  // outside the spot's cone: no photon may land
          CHECK(found.empty());
          continue;
        }
        if (expected < 0.1 * maxE) continue;  // a narrow lobe's tail: too few photons for z
        REQUIRE(found.size() >= 30);  // enough photons for the normal approximation
        double z = (sum / area - expected) / (std::sqrt(sum2) / area);
        INFO("x = (" << x.x << ", " << x.z << "): E " << sum / area << ", expected " << expected << ", z " << z);
        CHECK(std::abs(z) < 5.5);
        maxZ = std::max(maxZ, std::abs(z));
        sumZ2 += z * z;
        sumZ += z;
        ++n;
      }
    INFO("max |z| " << maxZ << ", mean z² " << sumZ2 / n << ", Σz/√n " << sumZ / std::sqrt(n) << ", n " << n);
    REQUIRE(n >= 30);
    CHECK(sumZ2 / n < 2.0);
    CHECK(std::abs(sumZ / std::sqrt(n)) < 4.0);
  }
}

// Renders the floor under `c` at W×W with seeds 1 and 2 (render(scene, seed)) and checks the
// two images against ρ/π·E per pixel (pixelAgreement).
template <typename RenderFn>
void checkPerPixel(const LightCase& c, int W, double medianMargin, RenderFn&& render) {
  auto scene = floorScene(c);
  ImageRGB expected = expectedFloorImage(*scene, W, W, [&](const Vec3& x) { return kRho / kPi * c.E(x); }, 8);
  checkAgreesPerPixel([&](uint64_t seed) { return render(*scene, seed); }, expected, medianMargin);
}

TEST_CASE("photons alone: PPM images of every light match ρ/π·E per pixel - median and 99th percentile", "[long]") {
  // PPM takes all light, direct included, from photons: 32×32 pixels, 24 passes of 100k paths,
  // initial radius 3 cm, seeds 1 and 2. Accepted: median ratio within 1 ± 0.02 (the per-pixel
  // noise is 8–15%, so its standard error over ~10³ pixels is < 0.6%), the mean ratio within
  // 1 ± 0.02, and the 99th percentile of |t| below 4.5 (3.25 for t₉; the margin covers the
  // neighbourhood's uneven noise). The directional light's bug gave a ratio of 0.126.
  for (const LightCase& c : lightCases()) {
    INFO(c.name);
    checkPerPixel(c, 32, 0.02, [](const Scene& scene, uint64_t seed) {
      RenderOptions ro;
      ro.width = ro.height = 32;
      ro.seed = seed;
      return makeWith("ppm", {{"passes", 24}, {"photons_per_pass", 100000}, {"radius", 0.03f}})->render(scene, ro, nullptr);
    });
  }
}

TEST_CASE("shadow rays alone: direct lighting of every light matches ρ/π·E per pixel") {
  // The direct integrator: one light sample per camera sample (delta lights: exact, so only
  // the pixel jitter varies; the area light: a solid-angle estimator), 32×32 pixels, 16 spp,
  // seeds 1 and 2. Same acceptance as the photons' test, with a 1% median (noise is ~3%).
  for (const LightCase& c : lightCases()) {
    INFO(c.name);
    checkPerPixel(c, 32, 0.01, [&](const Scene& scene, uint64_t seed) {
      auto direct = makeIntegrator("direct", {});
      RenderOptions ro;
      ro.width = ro.height = 32;
      ro.spp = 16 * c.effort;
      ro.seed = seed;
      return render(scene, *direct, ro, nullptr);
    });
  }
}

TEST_CASE("Sobol' sampler of the camera-side integrators: direct and path images of every light match ρ/π·E per pixel - and the area light's error falls") {
  // The camera-side integrators' Sobol' sampler (core/sampler.h): the pixel jitter, the light
  // pick and the point on the light are Owen-scrambled Sobol' points over the pixel's samples.
  // Each point is uniform on its own, so every pixel's expectation is the closed form's: the
  // shadow-ray test's acceptance above, for direct lighting and for the path tracer (next-event
  // estimation and BSDF sampling under MIS; the floor alone bounces nothing back). Seeds 1 and 2
  // are independent scrambles, so the t statistic's noise estimate from their difference holds.
  for (const char* integrator : {"direct", "path"})
    for (const LightCase& c : lightCases()) {
      INFO(integrator << ", " << c.name);
      checkPerPixel(c, 32, 0.01, [&](const Scene& scene, uint64_t seed) {
        RenderOptions ro;
        ro.width = ro.height = 32;
        ro.spp = 16 * c.effort;
        ro.seed = seed;
        return render(scene, *makeWith(integrator, {}, ro, {{"sampler", "sobol"}}), ro, nullptr);
      });
    }
  // What the points buy: the area light's direct lighting is a smooth integrand over the light
  // (4D with the jitter, two stratified pairs), whose Owen-scrambled estimate has a variance
  // falling faster than 1/n; at 64 spp the pixels' mean squared error against the closed form
  // must be below half the independent sampler's (measured: a fifth). Points that were not
  // stratified over a pixel's samples (the same scramble for every sample, the index unused,
  // the pairs of one sequence correlated) would give a ratio of 1 or worse. Two seeds each; the
  // expected image's own error (an 8×8 midpoint rule per pixel) is far below either.
  const LightCase area = lightCases()[4];
  REQUIRE(std::string(area.name) == "area");
  auto scene = floorScene(area);
  ImageRGB expected = expectedFloorImage(*scene, 32, 32, [&](const Vec3& x) { return kRho / kPi * area.E(x); }, 8);
  auto mse = [&](const char* sampler) {
    double sum = 0;
    for (uint64_t seed : {1, 2}) {
      RenderOptions ro;
      ro.width = ro.height = 32;
      ro.spp = 64;
      ro.seed = seed;
      ImageRGB img = render(*scene, *makeWith("direct", {}, ro, {{"sampler", sampler}}), ro, nullptr);
      for (size_t i = 0; i < img.data.size(); ++i) sum += (img.data[i] - expected.data[i]) * (img.data[i] - expected.data[i]);
    }
    return sum;
  };
  const double independent = mse("independent"), sobol = mse("sobol");
  INFO("mean squared error: independent " << independent << ", sobol " << sobol);
  CHECK(sobol < 0.5 * independent);
}

TEST_CASE("light tracing alone: every light's splats match ρ/π·E per pixel", "[long]") {
  // The light tracer: paths from sampleLe, the floor vertex connected to the camera (We, the
  // BSDF in importance mode), 32×32 pixels, 512 light paths per pixel, seeds 1 and 2. A pixel
  // receives the splats of the paths that land in its footprint, a Poisson count: from ~20 (a
  // point light's paths mostly miss the view) to ~100. A sum of a Poisson count has a median
  // below its mean by ~1/(3n), and at 64 paths per pixel the point light's median ratio was
  // 0.96 for a mean ratio of 0.994; at 512 the count is ≥ 150 and the median within 0.5% of the
  // mean. Then the photons' acceptance: median and mean within 1 ± 0.02, p99 |t| < 4.5.
  for (const LightCase& c : lightCases()) {
    INFO(c.name);
    checkPerPixel(c, 32, 0.02, [&](const Scene& scene, uint64_t seed) {
      RenderOptions ro;
      ro.width = ro.height = 32;
      ro.spp = 512 * c.effort;
      ro.seed = seed;
      return render(scene, *makeIntegrator("light", ro), ro, nullptr);
    });
  }
}

TEST_CASE("bidirectional: bdpt, vcm and bpm images of every light match ρ/π·E per pixel", "[long]") {
  // Every light through the bidirectional estimators: bdpt and vcm weigh next-event estimation
  // (sampleLi), light tracing (sampleLe, Camera::sampleWi) and, in vcm, merging against each
  // other with densities from pdfLi/pdfLe; bpm takes everything from merging. A wrong density
  // in any of them shifts the weights and the level. 32×32 pixels, seeds 1 and 2; merge radius
  // 3 cm as the PPM test; bdpt and vcm 64 iterations, bpm 2048: it has only its merges, and
  // pixels a merge radius apart share them, so the median over the pixels is far noisier than
  // ~10³ independent pixels' would be (under the point light, five seed pairs: 0.974–1.004 at
  // 512 iterations, 0.992–1.002 at 2048). Acceptance as the photons' test: median and mean within
  // 1 ± 0.02, p99 |t| < 4.5. The skies spread their light paths over a 25 m² disc and the radius
  // shrinks (r_i = r₁ i^((α−1)/2)), so a pixel's merges are a Poisson count of ~15 at 3 cm,
  // whose median sits 2% below its mean: they merge within 10 cm, which a uniform E on the floor
  // makes exact (the view ends 0.8 m from the floor's edge).
  for (const char* name : {"bdpt", "vcm", "bpm"})
    for (const LightCase& c : lightCases()) {
      INFO(name << ": " << c.name);
      checkPerPixel(c, 32, 0.02, [&](const Scene& scene, uint64_t seed) {
        RenderOptions ro;
        ro.width = ro.height = 32;
        ro.seed = seed;
        ro.spp = std::string(name) == "bpm" ? 2048 : 64;
        return makeWith(name, {{"spp", ro.spp}, {"radius", c.environment ? 0.1 : 0.03}})->render(scene, ro, nullptr);
      });
    }
}

TEST_CASE("guided: path guiding's images of every light match ρ/π·E per pixel - SD-tree and photon guides", "[long]") {
  // Path guiding weighs next-event estimation against directions drawn from the mixture of the
  // BSDF and the guide: both MIS weights with BSDF sampling's density, each hit divided by the
  // mixture's. At the area light, guided directions find the emitter as often as the guide
  // learned it is there (from the paths' own records, or from photons' incident directions). A
  // pair of weights that does not sum to one, or a hit divided by the wrong density, moves the
  // level there. 32×32 pixels, 64 spp (iterations 1, 2, 4, 8, 16, 33), seeds
  // 1 and 2; the shadow rays' acceptance with a 2% median (the area light's pixels are noisier
  // than direct lighting's: half their directions are not the light's).
  for (const char* guide : {"sdtree", "photons"})
    for (const LightCase& c : lightCases()) {
      INFO(guide << ": " << c.name);
      checkPerPixel(c, 32, 0.02, [&](const Scene& scene, uint64_t seed) {
        RenderOptions ro;
        ro.width = ro.height = 32;
        ro.seed = seed;
        ro.spp = 64;
        return makeWith("guided", {{"spp", 64}, {"photons", 20000}}, ro, {{"guide", guide}})->render(scene, ro, nullptr);
      });
    }
}

TEST_CASE("radiosity: a textured emitter's patches exit M = π·Le at their centroids, from their front only") {
  // The textured area light of lightCases() (Le(u) = texturedLe, u linear in x) cut into 4 cm
  // patches: each front patch's exitance is π·Le at its centroid (the midpoint rule, the method's
  // assumption of one value per patch); one-sided, so the emitter has no back patches.
  Scene scene;
  for (const LightCase& c : lightCases())
    if (std::string(c.name) == "area (textured)") c.add(scene);
  scene.commit();
  PatchMesh mesh(scene, 0.04f);
  for (const Patch& p : mesh.patches()) {
    INFO("centroid x " << p.centroid.x);
    CHECK(p.normal.y == Approx(-1.0f));
    const double u = 0.125 + 0.75 * (p.centroid.x + 0.3) / 0.6;
    CHECK(p.exitance.g == Approx(kPi * texturedLe(u)).epsilon(1e-4));
  }
  CHECK(mesh.size() == 2 * 19 * 19);  // two triangles, longest edge √(0.6² + 0.4²) = 0.721 m: 19 cuts
}

TEST_CASE("radiosity: every light over a floor gives ρ/π·E per pixel", "[long]") {
  // Radiosity's own paths for each light: delta lights shoot first (their irradiance at 16
  // shadow-rayed points per patch, Light::sampleLi), the area light is emitting patches
  // (form factors). The floor is cut to what the camera sees (2.4 m) and meshed into 5 cm
  // patches (4608); with nothing else in the scene B = ρE exactly. The solution is
  // deterministic and 256 jittered samples per pixel make the pixel average's own noise
  // < 0.1%: the error is the discretisation's. Smooth display interpolates vertex averages of
  // patch averages linearly: ~h²/8 · |E''| where E is smooth (< 0.5% of the peak for these
  // lights), and up to h/4 × the slope jump on a kink: the glTF spot's inner cone, where a²
  // clamps at 1, ~7% of the peak on the kink line, ~1% over a pixel. Accepted, as errors
  // relative to the image's peak: median < 0.2%, 99th percentile < 2%, and the image mean
  // within 0.5% (each patch's flux is right whatever the interpolation). A missing cosine, or
  // the wrong intensity, moves the pixels away from the light by 30% or more.
  for (const LightCase& c : lightCases()) {
    if (c.environment) continue;  // radiosity refuses a sky (test_environment.cpp)
    INFO(c.name);
    auto scene = floorScene(c, 1.2f);
    RenderOptions ro;
    ro.width = ro.height = 32;
    ro.spp = 256;
    ImageRGB image = makeWith("radiosity", {{"patch_size", 0.05}, {"spp", 256}}, ro)->render(*scene, ro, nullptr);
    ImageRGB expected = expectedFloorImage(*scene, 32, 32, [&](const Vec3& x) { return kRho * kInvPi * c.E(x); });
    const double mean = meanOf(expected);
    double peak = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) peak = std::max(peak, double(expected.at(x, y).g));
    std::vector<double> error;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        error.push_back(std::abs(image.at(x, y).g - expected.at(x, y).g) / peak);
      }
    std::sort(error.begin(), error.end());
    const double median = error[error.size() / 2], p99 = error[size_t(0.99 * (error.size() - 1))];
    INFO("median |error| / peak " << median << ", p99 " << p99 << ", mean ratio " << meanOf(image) / mean);
    CHECK(median < 0.002);
    CHECK(p99 < 0.02);
    CHECK(meanOf(image) / mean == Approx(1.0).epsilon(0.005));
  }
}

TEST_CASE("alpha BLEND: a sheet of alpha 0.5 passes half of the light and half of the view - per pixel by shadow rays, light tracing and photons") {
  // A black sheet (ρ = 0) of coverage α = 0.5 at y = 0.5 over the floor, a point light of
  // intensity I at y = 1 above it, the camera at 0.9 looking down through it. A camera ray
  // reaches the floor with probability 1 − α, and so does the light, so
  //   L = (1 − α)² ρ/π · I h/r³,  h = 1, r² = h² + x² + z²;
  // the sheet reflects nothing and the floor has nothing else to see. Each path kind meets the
  // sheet in its own query: camera rays and photons in closest hits, shadow rays and the light
  // tracer's connections in occlusion. Acceptance as the lights' tests: median and mean ratio
  // within 1 ± 0.02, p99 |t| < 4.5; the pass/block coin adds ~10% noise per pixel at these counts.
  const float alpha = 0.5f, I = 4.0f;
  Scene scene;
  addQuad(scene, {-kHalf, 0, -kHalf}, {-kHalf, 0, kHalf}, {kHalf, 0, kHalf}, {kHalf, 0, -kHalf}, lambertian(scene, kRho));
  Material sheet{"sheet", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(0), false};
  sheet.alphaMode = AlphaMode::Blend;
  sheet.alpha = std::make_shared<AlphaTexture>(alpha, nullptr, UvTransform{});
  uint32_t sheetMaterial = scene.addMaterial(std::move(sheet));
  addQuad(scene, {-kHalf, 0.5f, -kHalf}, {-kHalf, 0.5f, kHalf}, {kHalf, 0.5f, kHalf}, {kHalf, 0.5f, -kHalf}, sheetMaterial);
  scene.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(I)));
  scene.setCamera(lookingDown(0.9f));
  scene.commit();
  const int W = 32;
  ImageRGB expected = expectedFloorImage(scene, W, W, [&](const Vec3& x) {
    double r2 = 1.0 + x.x * x.x + x.z * x.z;
    return (1 - alpha) * (1 - alpha) * kRho / kPi * I / (r2 * std::sqrt(r2));
  }, 8);
  auto check = [&](const std::function<ImageRGB(uint64_t)>& render) { checkAgreesPerPixel(render, expected); };
  RenderOptions ro;
  ro.width = ro.height = W;
  SECTION("path: camera rays and shadow rays") {
    check([&](uint64_t seed) {
      ro.seed = seed, ro.spp = 256;
      return makeWith("path", {{"spp", 256}}, ro)->render(scene, ro, nullptr);
    });
  }
  SECTION("light tracing: photons and their connections to the camera") {
    check([&](uint64_t seed) {
      ro.seed = seed, ro.spp = 2048;
      return render(scene, *makeIntegrator("light", ro), ro, nullptr);
    });
  }
  SECTION("sppm: photons and camera rays") {
    // SPPM, not PPM: PPM's eye pass is traced once, so a pixel whose one camera ray met the
    // sheet stays black for good (right on average over pixels, not per pixel); SPPM draws a
    // new camera ray every pass.
    check([&](uint64_t seed) {
      ro.seed = seed;
      return makeWith("sppm", {{"passes", 64}, {"photons_per_pass", 50000}, {"radius", 0.03f}}, ro)->render(scene, ro, nullptr);
    });
  }
}

TEST_CASE("shading normals: photons scattered by a ceiling with tilted normals light the floor as the path tracer says") {
  // A Warn spotlight (s = 1) at half height aims at the ceiling (ρ = 0.8), whose vertex normals
  // all lean 27° off its face normal; the floor (ρ = 0.5, flat) sees no direct light, only what
  // the ceiling scatters. The path tracer reaches it through the ceiling's reflection equation
  // with the shading cosine (BSDF sampling, then next-event estimation); photons and light paths
  // leave the ceiling with Veach's adjoint correction |wo·ns||wi·ng|/(|wo·ng||wi·ns|); without it
  // PPM's floor had the right mean (0.5% off) but the wrong shape, regions at |z| up to 14. Region by region (4×4 regions of 4×4 pixels), each with
  // two seeds: z = (a − path)/σ from the seeds' differences, every |z| < 4 (a false alarm ~10⁻³
  // over 16 regions), mean z² < 3, the image means within 2%. PPM's radius (3 cm, shrinking)
  // blurs an irradiance that varies over ~0.5 m: its bias is far below the noise.
  Scene scene;
  const float h = 1.2f;
  addQuad(scene, {-h, 0, -h}, {-h, 0, h}, {h, 0, h}, {h, 0, -h}, lambertian(scene, 0.5f));
  const Vec3 tilted = glm::normalize(Vec3(0.5f, -1, 0));
  scene.addMesh({{-h, 1, -h}, {h, 1, -h}, {h, 1, h}, {-h, 1, h}}, {tilted, tilted, tilted, tilted}, {},
                {0, 1, 2, 0, 2, 3}, lambertian(scene, 0.8f));
  scene.addLight(std::make_unique<WarnSpotlight>(Vec3(0, 0.5f, 0), Vec3(0, 1, 0), Spectrum(1.0f), 1.0f));
  scene.setCamera(lookingDown(0.9f, 1.2f));
  scene.commit();
  SurfaceHit ceiling;
  REQUIRE(scene.intersect(Ray{Vec3(0, 0.5f, 0), Vec3(0, 1, 0), 0, INFINITY}, &ceiling));
  REQUIRE(ceiling.shadingDiffers());
  REQUIRE(glm::dot(ceiling.shading.n, ceiling.ng) == Approx(2 / std::sqrt(5.0)));

  RenderOptions ro;
  ro.width = ro.height = 16;
  auto renderWith = [&](const std::string& name, uint64_t seed) {
    RenderOptions o = ro;
    o.seed = seed;
    if (name == "path") o.spp = 256;
    if (name == "light") o.spp = 1024;
    if (name == "ppm") return makeWith("ppm", {{"passes", 16}, {"photons_per_pass", 100000}, {"radius", 0.03f}})->render(scene, o, nullptr);
    return render(scene, *makeIntegrator(name, o), o, nullptr);
  };
  ImageRGB p1 = renderWith("path", 1), p2 = renderWith("path", 2);
  for (const char* name : {"ppm", "light"}) {
    INFO(name);
    ImageRGB a1 = renderWith(name, 1), a2 = renderWith(name, 2);
    RegionAgreement r = regions(a1, a2, p1, p2, 4);
    INFO("mean z² " << r.meanZ2 << ", worst |z| " << r.worst << ", mean ratio "
                    << (meanOf(a1) + meanOf(a2)) / (meanOf(p1) + meanOf(p2)));
    CHECK(r.worst < 4.0);
    CHECK(r.meanZ2 < 3.0);
    CHECK((meanOf(a1) + meanOf(a2)) / (meanOf(p1) + meanOf(p2)) == Approx(1.0).epsilon(0.02));
  }
}

namespace {
// Renders by each named integrator at W × W, seeds 1 and 2, and checks them per pixel.
// `sppm`: its parameters; `vcm`: vcm's, where the default radius and iterations are too few.
void checkIntegratorsPerPixel(const Scene& scene, const ImageRGB& expected, const std::vector<std::string>& names,
                              const std::map<std::string, double>& sppmParams = {},
                              const std::map<std::string, double>& vcmParams = {}) {
  const int W = expected.width;
  for (const std::string& name : names) {
    INFO(name);
    checkAgreesPerPixel([&](uint64_t seed) {
      RenderOptions o;
      o.width = o.height = W;
      o.seed = seed;
      if (name == "sppm") return makeWith("sppm", sppmParams, o)->render(scene, o, nullptr);
      if (name == "vcm" && !vcmParams.empty()) {
        o.spp = int(vcmParams.at("spp"));
        return makeWith("vcm", vcmParams, o)->render(scene, o, nullptr);
      }
      const int spp = name == "light" ? 4096 : name == "path" ? 256 : 128;
      o.spp = spp;
      return makeWith(name, {{"spp", spp}}, o)->render(scene, o, nullptr);
    }, expected);
  }
}

Camera lookingUp(float height, float yfov = 0.8f) {
  Camera cam;
  cam.position = Vec3(0, height, 0);
  cam.forward = Vec3(0, 1, 0);
  cam.up = Vec3(0, 0, 1);
  cam.right = glm::cross(cam.forward, cam.up);
  cam.yfov = yfov;
  return cam;
}
}  // namespace

// ∫ g(cosθ) cosθ dω over the square of half-width `half` at height `height` above a point,
// centred over it, by the midpoint rule in (θ, φ) up to the square's edge θmax(φ) (φ over one
// eighth of the turn, by symmetry).
double overSquare(double height, double half, const std::function<double(double)>& g) {
  const int nPhi = 90, nTheta = 1500;
  double sum = 0;
  for (int a = 0; a < nPhi; ++a) {
    const double phi = (a + 0.5) / nPhi * kPi / 4;
    const double thetaMax = std::atan(half / (height * std::cos(phi)));
    const double dTheta = thetaMax / nTheta;
    for (int b = 0; b < nTheta; ++b) {
      const double theta = (b + 0.5) * dTheta, mu = std::cos(theta);
      sum += g(mu) * mu * std::sin(theta) * dTheta;
    }
  }
  return sum * (kPi / 4 / nPhi) * 8;
}

TEST_CASE("thin-walled transmission: a rough translucent wall passes the sun to the floor - seen from below it is f_t E - every path", "[long]") {
  // A white thin wall (metallic 0, roughness 0.5: α = 0.25, transmission 1) at height h = 0.25
  // under a directional light straight down (E = 3 W/m²), a floor (ρ = 0.5) below, both 4 m
  // wide. A wall point sends the sun's light down towards wo (μ = cosθ from straight down) with
  //   f_t(wo, ŷ) E,  f_t = (1 − F(wo·m)) D(m) G1(μ) G1(1) / (4 μ),  m = normalize(wo − ŷ)
  // (the light's direction mirrored through the wall; ggx_reference.h's formulas), so the
  // floor's centre receives E_t = E ∫ f_t(μ) μ dω over the wall's square (GGX's long tail makes
  // the square's edge matter: 2.7% of an infinite wall's light arrives beyond it). The floor
  // sends ρ E_f up; the underside reflects the specular layer's albedo E_F(μ) of it back
  // (Lambertian light: its mirror image of the floor, a square at 2h, bounds the integral), so
  //   E_f = E_t / (1 − ρ R),  R = (1/π) ∫ E_F(μ) μ dω over that square,  L_floor = ρ E_f / π.
  // Seen from below at wo the wall shows L(wo) = f_t(wo, ŷ) E + L_floor E_F(μ). The floor's view
  // needs the sun through the transmission lobe by next-event estimation, photons and light
  // subpaths; the wall's view needs photons gathered from its other side (BSDF::transmits) and
  // light tracing's connections through it.
  const float E = 3.0f, rhoF = 0.5f, half = 2.0f, h = 0.25f, roughness = 0.5f;
  const double alpha = roughness * roughness;
  auto ft = [&](double mu) {
    const glm::dvec3 wo(std::sqrt(1 - mu * mu), -mu, 0), down(0, -1, 0), m = glm::normalize(wo + down);
    return (1 - schlick004(glm::dot(wo, m))) * ggxD(glm::dot(m, down), alpha) * ggxG1(mu, alpha) * ggxG1(1.0, alpha) / (4 * mu);
  };
  const int nodes = 64;  // E_F on nodes of μ, linear between them
  std::vector<double> EF(nodes + 1);
  for (int j = 0; j <= nodes; ++j) EF[j] = lobeAlbedo(std::max(1e-3, double(j) / nodes), alpha, true, 200);
  auto albedoF = [&](double mu) {
    double f = mu * nodes;
    int j = std::min(int(f), nodes - 1);
    return EF[j] + (f - j) * (EF[j + 1] - EF[j]);
  };
  const double Et = E * overSquare(h, half, ft), R = overSquare(2 * h, half, albedoF) / kPi;
  const double Lfloor = rhoF * Et / (1 - rhoF * R) / kPi;
  auto build = [&](const Camera& camera) {
    auto scene = std::make_unique<Scene>();
    addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, lambertian(*scene, rhoF));
    uint32_t wall = scene->addMaterial({"thin wall", std::make_unique<MetallicRoughness>(ColorTexture(Spectrum(1.0f)),
                                        ColorTexture(Spectrum(1, roughness, 0)), ColorTexture(Spectrum(1.0f))), Spectrum(0), false});
    addQuad(*scene, {-half, h, -half}, {-half, h, half}, {half, h, half}, {half, h, -half}, wall);
    scene->addLight(std::make_unique<DirectionalLight>(Vec3(0, -1, 0), Spectrum(E)));
    scene->setCamera(camera);
    scene->commit();
    return scene;
  };
  const int W = 16;
  const std::map<std::string, double> sppm = {{"passes", 64}, {"photons_per_pass", 50000}, {"radius", 0.03}};
  SECTION("the floor, under the wall") {
    auto scene = build(lookingDown(0.12f, 1.4f));
    ImageRGB expected = expectedImage(*scene, W, W, [&](const Ray&) { return Lfloor; });
    checkIntegratorsPerPixel(*scene, expected, {"path", "light", "sppm", "bdpt", "vcm"}, sppm);
  }
  SECTION("the wall, from below") {
    auto scene = build(lookingUp(0.08f, 1.4f));
    ImageRGB expected = expectedImage(*scene, W, W, [&](const Ray& r) {
      const double mu = std::abs(r.d.y);
      return ft(mu) * E + Lfloor * albedoF(mu);
    });
    checkIntegratorsPerPixel(*scene, expected, {"path", "light", "sppm", "bdpt", "vcm"}, sppm);
  }
}

TEST_CASE("thin-walled transmission: a smooth pane passes (1 − F) T straight through - under a sky and under the sun - every path") {
  // A pane (ThinDielectric: η = 1.5, F0 = 0.04, tint T = 0.8) at height h over a floor
  // (ρ = 0.5), the camera above it looking down through it: a pixel sees
  //   L = (1 − F(μc)) T L_floor + F(μc) L_above,  F(μ) = F0 + (1 − F0)(1 − μ)⁵.
  // The floor's own light comes back from the pane's underside by mirror reflection: R = (1/π)
  // ∫ F(μ) μ dω over the floor's mirror image, a square at 2h (2∫F μ dμ = F0 + (1 − F0)/21 for
  // an infinite one: ∫(1 − μ)⁵ μ dμ = 1/42).
  //   Under a constant sky L_env, planes 40 m wide (h = 0.5): E_f = L_env ∫ (1 − F(μ)) T μ dω
  //   over the pane's square, + L_env π − ∫ μ dω (the sky past its edges), + ρ E_f R; L_above =
  //   L_env. Its light reaches the floor only by BSDF sampling through the delta pane (shadow
  //   rays are blocked by it): path and bdpt.
  //   Under the sun E straight down, planes 4 m wide (h = 0.25): E_f = E (1 − F(1)) T + ρ E_f R;
  //   L_above = 0 (the sun is a direction no camera ray meets). Its light reaches the floor only
  //   by photons and light subpaths: sppm and vcm.
  const float T = 0.8f, rhoF = 0.5f;
  const double F0 = 0.04;
  auto F = [&](double mu) { return F0 + (1 - F0) * std::pow(1 - mu, 5); };
  auto build = [&](float half, float h, float cameraHeight, std::unique_ptr<Light> light) {
    auto scene = std::make_unique<Scene>();
    addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, lambertian(*scene, rhoF));
    uint32_t pane = scene->addMaterial({"pane", std::make_unique<ThinDielectric>(ColorTexture(Spectrum(T)), 1.5f), Spectrum(0), false});
    addQuad(*scene, {-half, h, -half}, {-half, h, half}, {half, h, half}, {half, h, -half}, pane);
    scene->addLight(std::move(light));
    scene->setCamera(lookingDown(cameraHeight));
    scene->commit();
    return scene;
  };
  const int W = 16;
  SECTION("under a constant sky") {
    const double Lenv = 1.0, half = 20, h = 0.5;
    auto scene = build(float(half), float(h), 1.0f, EnvironmentLight::constant(Spectrum(float(Lenv))));
    const double R = overSquare(2 * h, half, F) / kPi;
    const double Ein = Lenv * (overSquare(h, half, [&](double mu) { return (1 - F(mu)) * T; }) + kPi -
                               overSquare(h, half, [](double) { return 1.0; }));
    const double Lfloor = rhoF * Ein / (1 - rhoF * R) / kPi;
    ImageRGB expected = expectedImage(*scene, W, W, [&](const Ray& r) {
      const double mu = std::abs(r.d.y);
      return (1 - F(mu)) * T * Lfloor + F(mu) * Lenv;
    });
    checkIntegratorsPerPixel(*scene, expected, {"path", "bdpt"});
  }
  SECTION("under the sun") {
    const double E = 3.0, half = 2, h = 0.25;
    auto scene = build(float(half), float(h), 0.6f, std::make_unique<DirectionalLight>(Vec3(0, -1, 0), Spectrum(float(E))));
    const double R = overSquare(2 * h, half, F) / kPi;
    const double Lfloor = rhoF * (E * (1 - F(1.0)) * T) / (1 - rhoF * R) / kPi;
    ImageRGB expected = expectedImage(*scene, W, W, [&](const Ray& r) { return (1 - F(std::abs(r.d.y))) * T * Lfloor; });
    // The floor's light is uniform, so wide gathers cost no bias and keep the counts per pixel
    // (and the skew of their few-photon medians) in hand.
    checkIntegratorsPerPixel(*scene, expected, {"sppm", "vcm"}, {{"passes", 64}, {"photons_per_pass", 50000}, {"radius", 0.06}},
                             {{"spp", 512}, {"radius", 0.1}});
  }
}

namespace {
// A closed box of `material`, every face wound counter-clockwise seen from outside.
void addBox(Scene& scene, const Vec3& lo, const Vec3& hi, uint32_t material) {
  const Vec3 centre = 0.5f * (lo + hi);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 c[4];
      for (int k = 0; k < 4; ++k) {
        c[k][axis] = side ? hi[axis] : lo[axis];
        c[k][u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        c[k][v] = (k >= 2) ? hi[v] : lo[v];
      }
      const Vec3 n = glm::cross(c[1] - c[0], c[2] - c[0]);
      const Vec3 out = 0.5f * (c[0] + c[2]) - centre;
      if (glm::dot(n, out) < 0) std::swap(c[1], c[3]);
      addQuad(scene, c[0], c[1], c[2], c[3], material);
    }
}
}  // namespace

TEST_CASE("KHR_materials_volume attenuation: a glass slab passes (1 − F)² a / (1 − F² a²) - Beer–Lambert on every path, camera side and light side", "[heavy]") {
  // A glass slab (η = 1.5) 0.2 m thick, 2 m wide, whose medium lets through attenuationColor
  // c = (0.5, 0.7, 0.9) per 0.1 m. A ray crossing it at θ (θ' inside, sinθ' = sinθ/η) goes
  // D/cosθ' through the medium, a = c^(D / (0.1 cosθ')) one way, and every internal reflection
  // pair adds F² a², F the exact unpolarised Fresnel reflectance at θ (written out here), so
  //   T(θ) = (1 − F)² a Σ (F² a²)ⁿ = (1 − F)² a / (1 − F² a²).
  // Below it, either an emitter (Le = 1, black) seen through it: L = T(θc) Le, which camera
  // paths carry (their segments inside the glass); or a floor (ρ = 0.05) under the sun (E = 3
  // straight down): L = T(θc) (ρ/π) E T(0), which needs photons and light subpaths attenuated
  // too. The floor's own light coming back from the slab, ρ·(the slab's reflectance to diffuse
  // light, < 0.12), adds at most 0.6%. The camera 1 m up looks down (0.8 rad). Per pixel, green,
  // and per channel the image means within 1.5% (2% for the sun's photon estimates).
  const Spectrum c(0.5f, 0.7f, 0.9f);
  const double eta = 1.5, D = 0.2, distance = 0.1;
  auto fresnel = [&](double cosI) {
    const double sinT2 = (1 - cosI * cosI) / (eta * eta), cosT = std::sqrt(1 - sinT2);
    const double rs = (cosI - eta * cosT) / (cosI + eta * cosT), rp = (eta * cosI - cosT) / (eta * cosI + cosT);
    return 0.5 * (rs * rs + rp * rp);
  };
  auto slabT = [&](double color, double cosTheta) {
    const double cosInside = std::sqrt(1 - (1 - cosTheta * cosTheta) / (eta * eta));
    const double a = std::pow(color, D / (distance * cosInside)), F = fresnel(cosTheta);
    return (1 - F) * (1 - F) * a / (1 - F * F * a * a);
  };
  auto build = [&](bool emitter, const Spectrum& color) {
    auto scene = std::make_unique<Scene>();
    const float half = 1.0f;
    if (emitter) {
      uint32_t m = scene->addMaterial({"emitter", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(1.0f), false});
      addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, m);
    } else {
      addQuad(*scene, {-half, 0, -half}, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, lambertian(*scene, 0.05f));
      scene->addLight(std::make_unique<DirectionalLight>(Vec3(0, -1, 0), Spectrum(3.0f)));
    }
    Material glass{"absorbing glass", std::make_unique<Dielectric>(float(eta)), Spectrum(0.0f), false};
    glass.attenuationColor = ColorTexture(color);
    glass.attenuationDistance = float(distance);
    addBox(*scene, {-half, 0.3f, -half}, {half, 0.5f, half}, scene->addMaterial(std::move(glass)));
    scene->setCamera(lookingDown(1.0f));
    scene->commit();
    return scene;
  };
  const int W = 16;
  // expected(ray, channel); `sun`: the photon methods' settings.
  auto check = [&](const Scene& scene, const std::string& name, const std::function<double(const Ray&, int)>& expected, double margin,
                   bool spectral = false) {
    INFO(name << (spectral ? " spectral" : ""));
    auto image = [&](uint64_t seed) {
      RenderOptions o;
      o.width = o.height = W;
      o.seed = seed;
      o.spectral = spectral;
      if (name == "sppm" || name == "ppm")
        return makeWith(name, {{"passes", 32}, {"photons_per_pass", 100000}, {"radius", 0.02}}, o)->render(scene, o, nullptr);
      o.spp = name == "vcm" ? 1024 : 64;
      return makeWith(name, {{"spp", o.spp}, {"photons", 200000}, {"caustic_photons", 400000}, {"radius", 0.05}}, o)
          ->render(scene, o, nullptr);
    };
    ImageRGB a = image(1), b = image(2);
    for (int k = 0; k < 3; ++k) {
      ImageRGB e = expectedImage(scene, W, W, [&](const Ray& r) { return expected(r, k); });
      double mean = 0, meanExpected = 0;
      for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x) mean += (a.at(x, y)[k] + b.at(x, y)[k]) / 2, meanExpected += e.at(x, y).g;
      INFO("channel " << k << ": mean " << mean / (W * W) << ", expected " << meanExpected / (W * W));
      CHECK(mean / meanExpected == Approx(1.0).epsilon(margin));
      if (k == 1) checkAgreesPerPixel([&](uint64_t seed) { return seed == 1 ? a : b; }, e);
    }
  };
  SECTION("an emitter seen through the slab: camera paths") {
    auto scene = build(true, c);
    auto expected = [&](const Ray& r, int k) { return slabT(c[k], std::abs(r.d.y)); };
    for (const char* name : {"path", "whitted", "bdpt", "vcm", "sppm", "photon"}) check(*scene, name, expected, 0.015);
    // Spectral: a grey medium (its uplifted spectrum is flat) attenuates every wavelength alike.
    auto grey = build(true, Spectrum(0.6f));
    check(*grey, "path", [&](const Ray& r, int) { return slabT(0.6, std::abs(r.d.y)); }, 0.015, true);
  }
  SECTION("a floor under the sun, seen through the slab: photons and light subpaths too") {
    auto scene = build(false, c);
    auto expected = [&](const Ray& r, int k) { return slabT(c[k], std::abs(r.d.y)) * 0.05 / kPi * 3.0 * slabT(c[k], 1.0); };
    // Not PPM: its eye pass is traced once, so a pixel whose one camera ray the slab reflected
    // stays black and the others carry 1/(1 − F)² (right on average, not per pixel).
    for (const char* name : {"sppm", "vcm", "photon"}) check(*scene, name, expected, 0.02);
  }
}

TEST_CASE("volume attenuation: a segment that ends on an absorbing volume's back face keeps c^(t/d) - one entering it, or in clear glass, keeps 1") {
  // Beer–Lambert with KHR_materials_volume's parameters: σ = −ln(c)/d, so exp(−σ t) = c^(t/d) per
  // channel, where t is the segment's length inside. The slab of the test above (y from 0.3 to
  // 0.5, c = (0.5, 0.7, 0.9) per d = 0.1 m): a ray from inside meets a back face, one from above
  // the front face, which ends a segment outside.
  const Spectrum c(0.5f, 0.7f, 0.9f);
  auto build = [&](const Spectrum& color) {
    auto scene = std::make_unique<Scene>();
    Material glass{"glass", std::make_unique<Dielectric>(1.5f), Spectrum(0.0f), false};
    glass.attenuationColor = ColorTexture(color);
    glass.attenuationDistance = 0.1f;
    addBox(*scene, {-1, 0.3f, -1}, {1, 0.5f, 1}, scene->addMaterial(std::move(glass)));
    scene->commit();
    return scene;
  };
  auto segment = [](const Scene& scene, const Vec3& o, const Vec3& d) {
    SurfaceHit hit;
    REQUIRE(scene.intersect(Ray{o, glm::normalize(d)}, &hit));
    return std::make_pair(hit.t, scene.transmittance(hit, glm::normalize(d), SampledWavelengths::rgb()));
  };
  auto scene = build(c);
  REQUIRE(scene->hasAbsorbingVolumes());
  struct Case { Vec3 o, d; double length; };
  const double slant = std::sqrt(1.1);  // |(0.3, ±1, 0.1)|
  for (const Case& k : {Case{{0.1f, 0.45f, 0.2f}, {0.3f, -1, 0.1f}, 0.15 * slant},  // down to the bottom face
                        Case{{0.1f, 0.45f, 0.2f}, {0.3f, 1, 0.1f}, 0.05 * slant},   // up to the top face
                        Case{{0.1f, 0.4f, 0.2f}, {1, 0, 0}, 0.9}}) {                // sideways to x = 1
    auto [t, T] = segment(*scene, k.o, k.d);
    INFO("from " << k.o.x << ", " << k.o.y << ", " << k.o.z);
    CHECK(t == Approx(k.length).epsilon(1e-5));
    for (int ch = 0; ch < 3; ++ch) CHECK(T[ch] == Approx(std::pow(double(c[ch]), k.length / 0.1)).epsilon(1e-5));
  }
  auto [tAbove, TAbove] = segment(*scene, {0.1f, 1, 0.2f}, {0, -1, 0});
  CHECK(tAbove == Approx(0.5));
  CHECK(TAbove == Spectrum(1.0f));
  auto clear = build(Spectrum(1.0f));
  CHECK_FALSE(clear->hasAbsorbingVolumes());
  CHECK(segment(*clear, {0.1f, 0.45f, 0.2f}, {0.3f, -1, 0.1f}).second == Spectrum(1.0f));
}
