// The environment light (lights/environment_light.h): its map convention and rotation, its
// sampling against its density (quadrature and chi-square), its photons' power, the closed
// forms it gives (a diffuse sphere under a constant sky is L = ρ·L_env; a white furnace of
// reflectance 1 is L_env everywhere) through every integrator that takes it, the spectral mode,
// and the ways a user gives one (glTF extras, --env, experiments) with their errors. The floor
// under a sky goes through the per-light tests of test_light_transport.cpp too.
#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include "cli_helpers.h"
#include "gltf_fixture.h"
#include "integrator_helpers.h"
#include "lights/environment_light.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"
#include "stats.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;

namespace {

// A map whose texels all differ (row j, column i), so that a mix-up of rows, columns or
// orientation changes every comparison below.
ImageRGB patternMap(int W, int H) {
  ImageRGB map(W, H);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i)
      map.set(i, j, Spectrum(0.1f + 0.05f * float((7 * i + 3 * j) % 11), 0.2f + 0.1f * float(j), 0.3f + 0.02f * float(i)));
  return map;
}

// The direction of map coordinates (u, v) by the convention's definition, unrotated:
// u = atan2(x, −z)/2π, v = acos(y)/π.
Vec3 directionOf(double u, double v) {
  double phi = 2 * kPi * u, theta = kPi * v;
  return Vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
}

// A UV sphere of radius r around c with smooth normals, outward.
void addSphere(Scene& scene, const Vec3& c, float r, uint32_t material, int rings = 48, int segments = 96) {
  std::vector<Vec3> p, n;
  std::vector<uint32_t> idx;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      Vec3 d = directionOf(double(j) / segments, double(i) / rings);
      p.push_back(c + r * d);
      n.push_back(d);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      uint32_t a = uint32_t(i * (segments + 1) + j), b = a + 1, cc = a + uint32_t(segments + 1), d = cc + 1;
      // Counter-clockwise seen from outside (φ turns clockwise about +Y).
      if (i > 0) idx.insert(idx.end(), {a, b, cc});
      if (i < rings - 1) idx.insert(idx.end(), {b, d, cc});
    }
  scene.addMesh(p, n, {}, idx, material);
}

Camera lookingAt(const Vec3& eye, const Vec3& target, float yfov) {
  Camera cam;
  cam.position = eye;
  cam.forward = glm::normalize(target - eye);
  cam.right = glm::normalize(glm::cross(cam.forward, Vec3(0, 1, 0)));
  cam.up = glm::cross(cam.right, cam.forward);
  cam.yfov = yfov;
  return cam;
}

// Pixels whose every one of 4×4 sub-pixel camera rays hits the scene's geometry (1), or misses
// it (0), as do their neighbours'; the silhouette's pixels are −1 and left out.
std::vector<int> coverage(const Scene& scene, int W, int H) {
  std::vector<int> c(size_t(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int hits = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          SurfaceHit hit;
          hits += scene.intersect(scene.camera().generateRay(x + (a + 0.5f) / 4, y + (b + 0.5f) / 4, W, H), &hit);
        }
      c[size_t(y) * W + x] = hits == 16 ? 1 : hits == 0 ? 0 : -1;
    }
  // A pixel's jittered samples reach past its 4×4 grid to its edges: a pixel next to a mixed
  // one may still touch the silhouette (a sphere's rim pixels read 2% over ρ·L_env for that).
  // Such pixels are left out too.
  std::vector<int> out = c;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int u = std::clamp(x + dx, 0, W - 1), v = std::clamp(y + dy, 0, H - 1);
          if (c[size_t(v) * W + u] != c[size_t(y) * W + x]) out[size_t(y) * W + x] = -1;
        }
  return out;
}

// Two seeds' renders a, b against a level e over the pixels of one class: the mean's z with
// the variance from the seeds' differences, σ² = mean(d²)/2 per pixel, and the 99th percentile
// of the per-pixel |t| = |x − e|/σ (salt noise around a right mean shows there).
struct LevelCheck {
  double mean = 0, z = 0, p99t = 0;
  double sigma = 0;  // the standard deviation of `mean`
  int pixels = 0;
};
LevelCheck level(const ImageRGB& a, const ImageRGB& b, const std::vector<int>& cls, int which, double e, int channel = 1) {
  LevelCheck r;
  double sum = 0, d2 = 0;
  for (size_t i = 0; i < cls.size(); ++i) {
    if (cls[i] != which) continue;
    double x = a.data[3 * i + channel], y = b.data[3 * i + channel];
    sum += (x + y) / 2;
    d2 += (x - y) * (x - y);
    ++r.pixels;
  }
  if (r.pixels == 0) return r;
  r.mean = sum / r.pixels;
  const double sigma = std::max(std::sqrt(d2 / r.pixels / 2), 1e-4 * e);  // per pixel
  r.sigma = sigma / std::sqrt(2.0 * r.pixels);
  r.z = (r.mean - e) / r.sigma;
  std::vector<double> t;
  for (size_t i = 0; i < cls.size(); ++i)
    if (cls[i] == which) t.push_back(std::abs(a.data[3 * i + channel] - e) / sigma);
  std::sort(t.begin(), t.end());
  r.p99t = t[size_t(0.99 * (t.size() - 1))];
  return r;
}

// The one-line error loading `path` gives, which names the file.
std::string loadError(const std::string& path, const GltfLoadOptions& options) {
  try {
    loadGltf(path, nullptr, options);
  } catch (const Error& e) {
    std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);
    CHECK_THAT(msg, Contains(path));
    return msg;
  }
  FAIL("loading " << path << " did not fail");
  return "";
}

struct Run {
  const char* name;
  std::map<std::string, double> values;
  bool seesSky = true;  // false: light tracing, which no light path shows the sky itself
};

// Every integrator that takes a sky, with settings for a 24×24 image.
std::vector<Run> skyRuns() {
  return {{"path", {{"spp", 64}}},
          {"guided", {{"spp", 64}}},
          // One shadow ray per sample, and half of a uniform sky's directions are below the
          // surface: twice the samples.
          {"direct", {{"spp", 128}}},
          {"whitted", {{"spp", 128}}},
          {"photon", {{"spp", 128}, {"photons", 200000}, {"radius", 0.02}}},
          {"ppm", {{"passes", 16}, {"photons_per_pass", 100000}, {"radius", 0.02}}},
          // One shadow ray per pass for the direct light: more passes, fewer photons.
          {"sppm", {{"passes", 128}, {"photons_per_pass", 25000}, {"radius", 0.02}}},
          {"pppm", {{"passes", 128}, {"photons_per_pass", 25000}, {"radius", 0.02}}},
          {"light", {{"spp", 256}}, false},
          // The sky through every technique: emission found, next-event estimation, light
          // subpaths from the bounding disc connected and merged.
          {"bdpt", {{"spp", 64}}},
          {"vcm", {{"spp", 64}, {"radius", 0.02}}},
          {"bpm", {{"spp", 1024}, {"radius", 0.05}}}};  // merges alone: a wider radius, still exact on a sphere
}

ImageRGB renderRun(const Scene& scene, const Run& run, uint64_t seed, int size, bool spectral = false) {
  RenderOptions ro;
  ro.width = ro.height = size;
  ro.seed = seed;
  ro.spectral = spectral;
  if (run.values.count("spp")) ro.spp = int(run.values.at("spp"));
  return makeWith(run.name, run.values, ro)->render(scene, ro, nullptr);
}

// The diffuse sphere (ρ = 0.6, radius 0.5) alone under a constant grey sky L = 0.75, seen from
// 3 m. Convex and alone, every point of it sees the sky over its whole hemisphere:
// E = π·L_env and L = ρ/π·E = ρ·L_env = 0.45; the camera rays that miss it see L_env.
std::unique_ptr<Scene> sphereUnderSky(float rho, const Spectrum& sky) {
  auto scene = std::make_unique<Scene>();
  addSphere(*scene, Vec3(0), 0.5f, lambertian(*scene, rho));
  scene->addLight(EnvironmentLight::constant(sky));
  scene->setCamera(lookingAt(Vec3(0, 0, 3), Vec3(0), 0.5f));
  scene->commit();
  return scene;
}

}  // namespace

TEST_CASE("environment map: the convention - row 0 at the zenith, u = atan2(x, -z)/2π - and the rotation about +Y") {
  const int W = 16, H = 8;
  ImageRGB map = patternMap(W, H);
  EnvironmentLight sky(map, 0.0f, "pattern");
  const SampledWavelengths rgb;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      Vec3 d = directionOf((i + 0.5) / W, (j + 0.5) / H);  // the texel's centre
      Spectrum L = sky.radiance(d, rgb), m = map.at(i, j);
      INFO("texel " << i << ", " << j);
      CHECK(L.r == m.r);
      CHECK(L.g == m.g);
      CHECK(L.b == m.b);
      // The sky's own L(y, w): radiance leaving it in w, i.e. arriving from −w.
      CHECK(sky.L(Vec3(0), -d, rgb).r == m.r);
    }
  // Straight up is row 0; u = 0 is −z, a quarter turn on (u = 1/4) is +x.
  CHECK(sky.texel(Vec3(0, 1, 0)).second == 0);
  CHECK(sky.texel(Vec3(0, -1, 0)).second == H - 1);
  CHECK(sky.texel(glm::normalize(Vec3(0.01f, 0, -1))) == std::make_pair(0, H / 2));
  CHECK(sky.texel(glm::normalize(Vec3(1, 0, 0.01f))) == std::make_pair(W / 4, H / 2));
  // Rotated by 90° about +Y, the sky seen in direction R·d is what the unrotated one shows in d
  // (R by glm, counter-clockwise seen from +Y: +x turns to −z).
  EnvironmentLight turned(map, 90.0f, "turned");
  const glm::mat4 R = glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 1, 0));
  CHECK(glm::length(Vec3(R * glm::vec4(1, 0, 0, 0)) - Vec3(0, 0, -1)) < 1e-6f);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      Vec3 d = directionOf((i + 0.5) / W, (j + 0.5) / H);
      Vec3 rd = Vec3(R * glm::vec4(d, 0.0f));
      CHECK(turned.radiance(rd, rgb).g == map.at(i, j).g);
      CHECK(turned.radiance(rd, rgb).r == map.at(i, j).r);
    }
}

TEST_CASE("environment map: the density integrates to 1, is proportional to luminance, and sampling follows it (chi-square)") {
  const int W = 8, H = 4;
  ImageRGB map = patternMap(W, H);
  map.set(3, 1, Spectrum(0.0f));  // a black texel: never sampled
  EnvironmentLight sky(map, 30.0f, "pattern");
  // Texel (i, j)'s share by its definition: Y_ij·Δω_j / Σ Y·Δω, Δω_j = (2π/W)(cosθ_j − cosθ_j+1).
  auto dOmega = [&](int j) { return 2 * kPi / W * (std::cos(kPi * j / H) - std::cos(kPi * (j + 1) / H)); };
  auto Y = [&](int i, int j) {
    Spectrum c = map.at(i, j);
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
  };
  double total = 0;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) total += Y(i, j) * dOmega(j);
  // ∫ p dω by the midpoint rule on 720 × 360 cells uniform in (φ, cosθ) (equal solid angle):
  // cells straddling a texel edge make its error ~1e-3 at most.
  double integral = 0;
  const int nu = 720, nv = 360;
  for (int a = 0; a < nu; ++a)
    for (int b = 0; b < nv; ++b) {
      double phi = 2 * kPi * (a + 0.5) / nu, cosTheta = 1 - 2 * (b + 0.5) / nv, s = std::sqrt(1 - cosTheta * cosTheta);
      integral += sky.pdf(Vec3(float(s * std::sin(phi)), float(cosTheta), float(-s * std::cos(phi)))) * 4 * kPi / (nu * nv);
    }
  CHECK(integral == Approx(1.0).margin(2e-3));
  // Sampling: 400k directions into 2×2 sub-cells of each texel in (φ, cosθ), un-rotating them
  // by the definition (−30° about +Y). Expected count: N × the texel's share / 4 (uniform in
  // solid angle inside a texel); the density each sample reports is Y_ij/Σ Y·Δω.
  const glm::mat4 unrotate = glm::rotate(glm::mat4(1.0f), glm::radians(-30.0f), glm::vec3(0, 1, 0));
  const int N = 400000;
  std::vector<double> observed(size_t(W * H * 4), 0.0), expected(size_t(W * H * 4), 0.0);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i)
      for (int k = 0; k < 4; ++k) expected[size_t((j * W + i) * 4 + k)] = N * Y(i, j) * dOmega(j) / total / 4;
  Rng rng(5);
  int badPdf = 0, blackHits = 0;
  for (int n = 0; n < N; ++n) {
    float pdf;
    Vec3 d = sky.sampleDirection(Vec2(rng.uniform(), rng.uniform()), &pdf);
    Vec3 l = Vec3(unrotate * glm::vec4(d, 0.0f));
    double u = std::atan2(double(l.x), -double(l.z)) / (2 * kPi);
    if (u < 0) u += 1;
    double c = std::clamp(double(l.y), -1.0, 1.0);
    int i = std::min(int(u * W), W - 1), j = std::min(int(std::acos(c) / kPi * H), H - 1);
    double c0 = std::cos(kPi * j / H), c1 = std::cos(kPi * (j + 1) / H);
    int su = std::min(int((u * W - i) * 2), 1), sv = std::min(int((c0 - c) / (c0 - c1) * 2), 1);
    observed[size_t((j * W + i) * 4 + sv * 2 + su)] += 1;
    blackHits += i == 3 && j == 1;
    badPdf += std::abs(pdf - float(Y(i, j) / total)) > 1e-4f * pdf;
  }
  CHECK(blackHits == 0);
  CHECK(badPdf < N / 1000);  // only samples on a texel edge may land in the neighbour by rounding
  double p = chiSquarePValue(observed, expected);
  INFO("chi-square p = " << p);
  CHECK(p > 1e-3);
}

TEST_CASE("environment light: power is πR²·∫L dω, and its photons carry it") {
  // Constant sky L = (1, 2, 3): ∫L dω = 4πL. The scene's bounding radius R = √3/2·(side) for a
  // unit cube's floor... here a 2 m × 2 m quad: R = √2.
  Scene scene;
  addQuad(scene, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, lambertian(scene, 0.5f));
  scene.addLight(EnvironmentLight::constant(Spectrum(1, 2, 3)));
  scene.commit();
  const EnvironmentLight& sky = *scene.environment();
  const double R = std::sqrt(2.0);
  CHECK(sky.integral().g == Approx(4 * kPi * 2).epsilon(1e-5));
  CHECK(sky.power().b == Approx(kPi * R * R * 4 * kPi * 3).epsilon(1e-5));
  // Mean photon flux over 100k emissions: Φ (exactly, per photon, for a constant sky), every
  // photon leaving the disc of radius R one radius out, heading into the bounding sphere.
  Rng rng(3);
  double flux = 0;
  int outside = 0;
  const SampledWavelengths rgb;
  for (int n = 0; n < 100000; ++n) {
    EmittedRay e = sky.sampleLe(Vec2(rng.uniform(), rng.uniform()), Vec2(rng.uniform(), rng.uniform()), rgb);
    flux += e.flux.g;
    // The ray's closest approach to the centre is within R (it crosses the bounding sphere).
    Vec3 o = e.ray.o, d = e.ray.d;
    outside += glm::length(o - glm::dot(o, d) * d) > R * 1.0001;
    CHECK(glm::dot(o, d) < 0);  // towards the scene
  }
  CHECK(outside == 0);
  CHECK(flux / 100000 == Approx(sky.power().g).epsilon(1e-4));
}

TEST_CASE("environment: a diffuse sphere under a constant sky is L = ρ·L_env, the sky itself L_env, in every integrator", "[heavy]") {
  // 24×24 pixels, seeds 1 and 2; the sphere's interior pixels (all 16 sub-pixel rays on it)
  // and the sky's (none). Accepted on the sphere: the mean's |z| < 4 from the seeds' own noise,
  // with that noise below 1% of the level (so a 4% error cannot pass), and the 99th percentile
  // of the per-pixel |t| below 4.5 (no salt noise around the right mean). Photon mapping's
  // radius (2 cm on a 0.5 m sphere) adds no bias here: a ball of radius r cuts an area of
  // exactly πr² from a sphere (Archimedes), whatever its curvature.
  const float rho = 0.6f, Lenv = 0.75f;
  auto scene = sphereUnderSky(rho, Spectrum(Lenv));
  std::vector<int> cls = coverage(*scene, 24, 24);
  for (const Run& run : skyRuns()) {
    INFO(run.name);
    ImageRGB a = renderRun(*scene, run, 1, 24), b = renderRun(*scene, run, 2, 24);
    LevelCheck s = level(a, b, cls, 1, rho * Lenv);
    INFO("sphere: mean " << s.mean << " (" << rho * Lenv << "), z " << s.z << ", p99 |t| " << s.p99t << ", " << s.pixels << " px");
    REQUIRE(s.pixels > 80);
    CHECK(s.sigma < 0.01 * rho * Lenv);  // the test sees a 4% error at 4σ
    CHECK(std::abs(s.z) < 4);
    CHECK(s.p99t < 4.5);
    if (!run.seesSky) continue;
    LevelCheck k = level(a, b, cls, 0, Lenv);
    INFO("sky: mean " << k.mean << ", " << k.pixels << " px");
    REQUIRE(k.pixels > 100);
    CHECK(k.mean == Approx(Lenv).epsilon(1e-5));  // camera rays see it exactly
  }
}

TEST_CASE("environment: the default overcast sky is CIE's L_z (1 + 2 cosθ)/3 over a ground of albedo 0.3, mean 1 - an open floor under it is ρ·7L_z/9") {
  // Independent numbers: the sky's mean over the sphere is (2/3 + 0.7/3)/2 · L_z = 0.45 L_z, so
  // L_z = 20/9; the ground is (0.7/3) L_z; the irradiance of an open upward surface is
  // ∫ L cosθ dω = (2π L_z/3)(1/2 + 2/3) = 7π L_z/9.
  const double Lz = 20.0 / 9.0;
  const ImageRGB map = overcastSky(Spectrum(1.0f));
  REQUIRE(map.width == 1);
  const int H = map.height;
  CHECK(map.at(0, 0).g == Approx(Lz).epsilon(1e-3));                  // the zenith's band
  CHECK(map.at(0, H / 2 - 1).g == Approx(Lz / 3).epsilon(0.02));      // just above the horizon
  CHECK(map.at(0, H / 2).g == Approx(0.7 / 3 * Lz).epsilon(1e-5));    // the ground
  CHECK(map.at(0, H - 1).g == Approx(0.7 / 3 * Lz).epsilon(1e-5));
  auto sky = makeEnvironment(defaultEnvironment(), nullptr, "default");
  CHECK(sky->integral().r == Approx(4 * kPi).epsilon(1e-5));
  CHECK_THAT(sky->description(), Contains("overcast sky (CIE), mean radiance 1, 1, 1"));
  CHECK(parseEnvironment("overcast", "--env").sky == "overcast");
  // Per pixel, path traced: a Lambertian floor of ρ = 0.5 seen from above, nothing else.
  const float rho = 0.5f;
  Scene scene;
  addQuad(scene, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, lambertian(scene, rho));
  scene.addLight(makeEnvironment(defaultEnvironment(), nullptr, "default"));
  scene.setCamera(lookingDown(1.0f, 0.8f));
  scene.commit();
  const ImageRGB expected = expectedFloorImage(scene, 16, 16, [&](const Vec3&) { return rho * 7 * Lz / 9; });
  checkAgreesPerPixel(
      [&](uint64_t seed) {
        RenderOptions o;
        o.width = o.height = 16;
        o.spp = 64;
        o.seed = seed;
        return makeWith("path", {{"spp", 64}}, o)->render(scene, o, nullptr);
      },
      expected);
}

TEST_CASE("environment: a white furnace - reflectance 1 under a constant sky - is L_env everywhere", "[long]") {
  // A floor, a wall behind it and a sphere on the floor, all Lambertian with ρ = 1, under
  // L_env = 0.5: radiance is L_env at every point and in every direction (nothing absorbs, and
  // the sky is uniform), however the light bounces between wall, floor and sphere. Paths end
  // only by escaping (Russian roulette keeps q = 1 at ρ = 1), or at max_depth 64 after ~2⁻⁶⁴ of
  // their weight. Pixels on the geometry, seeds 1 and 2: as the sphere's test, with photon
  // mapping's tolerance 3% (the wall–floor crease: a gather disc there reaches past the floor's
  // edge, into space where no floor receives photons).
  const float Lenv = 0.5f;
  Scene scene;
  uint32_t white = lambertian(scene, 1.0f);
  addQuad(scene, {-1.5f, 0, -1}, {-1.5f, 0, 1.5f}, {1.5f, 0, 1.5f}, {1.5f, 0, -1}, white);
  addQuad(scene, {-1.5f, 0, -1}, {1.5f, 0, -1}, {1.5f, 2, -1}, {-1.5f, 2, -1}, white);
  addSphere(scene, Vec3(0, 0.4f, 0), 0.4f, white, 24, 48);
  scene.addLight(EnvironmentLight::constant(Spectrum(Lenv)));
  scene.setCamera(lookingAt(Vec3(0, 1.2f, 3.2f), Vec3(0, 0.5f, 0), 0.9f));
  scene.commit();
  std::vector<int> cls = coverage(scene, 24, 24);
  for (const Run& run : skyRuns()) {
    if (std::string(run.name) == "direct" || std::string(run.name) == "whitted") continue;  // one bounce only
    INFO(run.name);
    ImageRGB a = renderRun(scene, run, 1, 24), b = renderRun(scene, run, 2, 24);
    LevelCheck g = level(a, b, cls, 1, Lenv);
    INFO("geometry: mean " << g.mean << ", z " << g.z << ", p99 |t| " << g.p99t << ", " << g.pixels << " px");
    REQUIRE(g.pixels > 200);
    const bool density = std::string(run.name) != "path" && std::string(run.name) != "guided" && std::string(run.name) != "light";
    CHECK(g.mean == Approx(Lenv).epsilon(density ? 0.03 : 0.01));
    if (!density) CHECK(std::abs(g.z) < 4);
    CHECK(g.p99t < 4.5);
  }
}

TEST_CASE("environment: spectral mode sees a coloured sky as RGB mode does") {
  // The sky's colour is uplifted to an emission spectrum (times D65) and integrated back by the
  // film: the sky pixels' RGB within 1.5% of the sky's (the uplift's fit), the sphere's
  // (ρ = 0.6 grey) within 2% of ρ·L_env per channel.
  const Spectrum sky(0.8f, 0.9f, 1.0f);
  auto scene = sphereUnderSky(0.6f, sky);
  std::vector<int> cls = coverage(*scene, 24, 24);
  Run path{"path", {{"spp", 64}}};
  ImageRGB a = renderRun(*scene, path, 1, 24, true), b = renderRun(*scene, path, 2, 24, true);
  for (int c = 0; c < 3; ++c) {
    INFO("channel " << c);
    LevelCheck k = level(a, b, cls, 0, sky[c], c), s = level(a, b, cls, 1, 0.6 * sky[c], c);
    CHECK(k.mean == Approx(sky[c]).epsilon(0.015));
    CHECK(s.mean == Approx(0.6 * sky[c]).epsilon(0.02));
  }
}

TEST_CASE("environment: the same image whatever the thread count") {
  auto scene = sphereUnderSky(0.6f, Spectrum(0.75f));
  for (const char* name : {"path", "sppm", "light", "vcm"}) {
    INFO(name);
    RenderOptions ro;
    ro.width = ro.height = 16;
    ro.spp = 4;
    std::map<std::string, double> v = {{"spp", 4}, {"passes", 2}, {"photons_per_pass", 20000}};
    ro.threads = 1;
    ImageRGB one = makeWith(name, v, ro)->render(*scene, ro, nullptr);
    ro.threads = 2;
    ImageRGB two = makeWith(name, v, ro)->render(*scene, ro, nullptr);
    CHECK(one.data == two.data);
  }
}

TEST_CASE("environment: radiosity, which does not take a sky, says so") {
  auto scene = sphereUnderSky(0.6f, Spectrum(0.75f));
  RenderOptions ro;
  ro.width = ro.height = 8;
  ro.spp = 1;
  try {
    makeWith("radiosity", {{"spp", 1}}, ro)->render(*scene, ro, nullptr);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(std::string(e.what()), Contains("radiosity: an environment light is not supported"));
  }
}

TEST_CASE("environment spec: --env text, and the errors for bad values, files and maps") {
  EnvironmentSpec grey = parseEnvironment("0.5", "--env");
  CHECK(grey.enabled);
  CHECK(grey.map.empty());
  CHECK(grey.radiance == Spectrum(0.5f));
  EnvironmentSpec rgb = parseEnvironment("1,2,3.5", "--env");
  CHECK(rgb.radiance == Spectrum(1, 2, 3.5f));
  CHECK(parseEnvironment("skies/noon.exr", "--env").map == "skies/noon.exr");
  CHECK_THROWS_WITH(parseEnvironment("-1", "--env"), Contains("--env") && Contains(">= 0"));
  CHECK_THROWS_WITH(parseEnvironment("nan", "--env"), Contains("finite"));
  CHECK_THROWS_WITH(parseEnvironment("1,2", "--env"), Contains("R,G,B"));
  CHECK_THROWS_WITH(parseEnvironment("1,x,2", "--env"), Contains("R,G,B"));
  // Maps: through a reader (the io layer's in the program; the test's here).
  const std::string dir = GltfFixture::dir();
  const std::string file = dir + "/env-spec.exr";
  { std::ofstream(file) << "stands in for an image"; }
  auto reader = [](ImageRGB image) { return [image](const std::string&) { return image; }; };
  EnvironmentSpec spec;
  spec.enabled = true;
  spec.map = file;
  spec.scale = 2;
  auto sky = makeEnvironment(spec, reader(patternMap(4, 2)), "--env");
  CHECK(sky->map().at(1, 1).g == Approx(2 * patternMap(4, 2).at(1, 1).g));
  ImageRGB bad = patternMap(4, 2);
  bad.set(2, 1, Spectrum(1, NAN, 1));
  CHECK_THROWS_WITH(makeEnvironment(spec, reader(bad), "--env"), Contains(file) && Contains("finite"));
  bad.set(2, 1, Spectrum(1, -1, 1));
  CHECK_THROWS_WITH(makeEnvironment(spec, reader(bad), "--env"), Contains(">= 0"));
  CHECK_THROWS_WITH(makeEnvironment(spec, reader(ImageRGB(4, 2)), "--env"), Contains("black"));
  spec.map = dir + "/missing.exr";
  CHECK_THROWS_WITH(makeEnvironment(spec, reader(patternMap(4, 2)), "--env"),
                    Contains("--env") && Contains("file not found") && Contains("missing.exr"));
}

TEST_CASE("environment in glTF: extras.photonlab.environment - radiance or a map beside the file - and its errors") {
  const std::string dir = GltfFixture::dir();
  GltfFixture g;
  g.doc["extras"] = {{"photonlab", {{"environment", {{"radiance", {0.2, 0.4, 0.6}}}}}}};
  auto scene = loadGltf(g.write("env-sky.gltf"));
  REQUIRE(scene->environment());
  CHECK(scene->lights().size() == 2);  // the fixture's point light too
  CHECK(scene->environment()->integral().b == Approx(4 * kPi * 0.6).epsilon(1e-5));
  CHECK_THAT(scene->environmentSource, Contains("extras.photonlab.environment"));
  // --env (GltfLoadOptions::environment) replaces the file's.
  GltfLoadOptions o;
  o.environment = parseEnvironment("3", "--env");
  CHECK(loadGltf(g.write("env-sky.gltf"), nullptr, o)->environment()->integral().b == Approx(4 * kPi * 3).epsilon(1e-5));
  // A map, resolved against the file's folder and read by the options' reader.
  { std::ofstream(dir + "/noon.hdr") << "stands in for an image"; }
  std::string seen;
  o = {};
  o.readImage = [&](const std::string& path) {
    seen = path;
    return patternMap(8, 4);
  };
  g.doc["extras"]["photonlab"]["environment"] = {{"map", "noon.hdr"}, {"rotate", 45}, {"scale", 0.5}};
  scene = loadGltf(g.write("env-map.gltf"), nullptr, o);
  CHECK(seen == dir + "/noon.hdr");
  REQUIRE(scene->environment());
  CHECK(scene->environment()->map().at(2, 1).g == Approx(0.5f * patternMap(8, 4).at(2, 1).g));
  auto error = [&](json environment) {
    g.doc["extras"]["photonlab"]["environment"] = environment;
    return loadError(g.write("env-bad.gltf"), o);
  };
  CHECK_THAT(error({{"radiance", -1}}), Contains("extras.photonlab.environment.radiance"));
  CHECK_THAT(error({{"radiance", 1}, {"map", "noon.hdr"}}), Contains("either radiance or map"));
  CHECK_THAT(error({{"radiance", 1}, {"sun", 1}}), Contains("extras.photonlab.environment.sun") && Contains("unknown key"));
  CHECK_THAT(error({{"map", "absent.exr"}}), Contains("extras.photonlab.environment") && Contains("file not found"));
  CHECK_THAT(error({{"radiance", 1}, {"scale", -2}}), Contains("scale"));
  CHECK_THAT(error(5), Contains("must be an object"));
}
