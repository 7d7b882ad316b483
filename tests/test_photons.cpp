// Photon mapping: the photon record, the kd-tree against brute force, power conservation,
// density estimation against closed forms, and the photon integrator against the path tracer.
#include <catch2/catch.hpp>

#include <algorithm>
#include <tuple>

#include "bsdfs/lambertian.h"
#include "bsdfs/mirror.h"
#include "core/sampling.h"
#include "integrators/photon.h"
#include "integrators/registry.h"
#include "lights/directional_light.h"
#include "lights/environment_light.h"
#include "lights/point_light.h"
#include "lights/warn_spotlight.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "stats.h"

using namespace pl;

namespace {

std::string scenePath(const char* name) { return std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name; }

uint32_t addQuad(Scene& scene, Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
  scene.addMesh({a, b, c, d}, {}, {}, {0, 1, 2, 0, 2, 3}, material);
  return material;
}

uint32_t lambertian(Scene& scene, float rho) {
  return scene.addMaterial({"diffuse", std::make_unique<Lambertian>(ColorTexture(Spectrum(rho))), Spectrum(0), false});
}

Camera lookingDown(float height) {
  Camera cam;
  cam.position = Vec3(0, height, 0);
  cam.forward = Vec3(0, -1, 0);
  cam.up = Vec3(0, 0, -1);
  cam.right = glm::cross(cam.forward, cam.up);
  return cam;
}

// A closed sphere of radius R around the origin, tessellated finely, with a given albedo.
void addSphere(Scene& scene, float R, uint32_t material) {
  std::vector<Vec3> p;
  std::vector<uint32_t> idx;
  const int rings = 64, segments = 128;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      float t = kPi * i / rings, f = 2 * kPi * j / segments;
      p.push_back(R * Vec3(std::sin(t) * std::cos(f), std::cos(t), std::sin(t) * std::sin(f)));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      uint32_t a = i * (segments + 1) + j, b = a + segments + 1;
      idx.insert(idx.end(), {a, a + 1, b, a + 1, b + 1, b});
    }
  scene.addMesh(p, {}, {}, idx, material);
}

double mean(const ImageRGB& img) {
  double s = 0;
  for (float v : img.data) s += v;
  return s / img.data.size();
}

}  // namespace

TEST_CASE("photon record: 20 bytes - RGBE flux unbiased to 1/256 - octahedral direction - path type") {
  CHECK(sizeof(Photon) == 20);
  Rng rng(1, 1);
  double sumRel = 0, sumSame = 0;
  const int N = 20000;
  for (int i = 0; i < N; ++i) {
    Spectrum f(rng.uniform(), rng.uniform(), rng.uniform());
    f *= std::pow(10.0f, 12 * rng.uniform() - 9);  // 1e-9 .. 1e3 W
    Vec3 w = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    Photon::Type type = Photon::Type(i % 3);
    Photon p(Vec3(1, 2, 3), w, f, type, rng.uniform());
    Spectrum g = p.flux();
    float m = maxComponent(f);
    for (int c = 0; c < 3; ++c) REQUIRE(std::abs(g[c] - f[c]) <= m / 128.0f);
    sumRel += (g.g - f.g) / m;
    REQUIRE(glm::length(p.wi() - w) < 2e-4f);  // ~0.01°
    REQUIRE(p.type() == type);
    // Identical photons (one white light): dithering keeps the sum unbiased.
    sumSame += Photon(Vec3(0), w, Spectrum(1e-4f), type, rng.uniform()).flux().g;
  }
  CHECK(std::abs(sumRel / N) < 2e-4);  // no systematic loss or gain of flux
  CHECK(sumSame / N == Approx(1e-4).epsilon(2e-4));
  // Round-to-nearest would be off by 0.14% for this value: 1e-4 = 209.7 × 2^-21.
  CHECK(Photon(Vec3(0), Vec3(0, 0, 1), Spectrum(1e-4f), Photon::kDirect, 0.5f).flux().g == Approx(1.00144e-4).epsilon(1e-4));
}

TEST_CASE("photon record: the encoding's SIMD path equals its portable reference bit for bit") {
  // On x86 the constructor packs flux and direction with SSE2; Photon::mantissa, octahedral
  // and quantise are the portable forms (used elsewhere). Edge cases first: negative, zero
  // and NaN channels, axes and the octahedron's seams, where a wrong operand order shows.
  Rng rng(9, 9);
  std::vector<Spectrum> fluxes = {Spectrum(1, 0, 0), Spectrum(-1, 2, 0.5f), Spectrum(3, NAN, 1), Spectrum(255.9f, 0, 1e-3f)};
  std::vector<Vec3> dirs = {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0),
                            glm::normalize(Vec3(1, -1, 0)), glm::normalize(Vec3(-1, 1, -1e-7f)), Vec3(0, -0.0f, -1)};
  for (int i = 0; i < 100000; ++i) {
    fluxes.push_back(Spectrum(rng.uniform(), rng.uniform(), rng.uniform()) * std::pow(10.0f, 12 * rng.uniform() - 9));
    dirs.push_back(sampleUniformSphere(Vec2(rng.uniform(), rng.uniform())));
  }
  for (size_t i = 0; i < fluxes.size(); ++i) {
    const Spectrum& f = fluxes[i];
    const Vec3& w = dirs[i % dirs.size()];
    float dither = i < 8 ? 0.999f : rng.uniform();
    auto type = Photon::Type(i % 3);
    Photon p(Vec3(0), w, f, type, dither);
    // The shared exponent, then the reference mantissas.
    float scale;
    int e = Photon::sharedExponent(maxComponent(f), dither, &scale);
    INFO("photon " << i);
    REQUIRE(p.rgbe[0] == Photon::mantissa(f.r, scale, dither));
    REQUIRE(p.rgbe[1] == Photon::mantissa(f.g, scale, dither));
    REQUIRE(p.rgbe[2] == Photon::mantissa(f.b, scale, dither));
    REQUIRE(p.rgbe[3] == uint8_t(e + 128));
    Vec2 uv = Photon::octahedral(w, 1.0f / (std::abs(w.x) + std::abs(w.y) + std::abs(w.z)));
    REQUIRE(p.direction[0] == uint16_t(Photon::quantise(uv.x) << 1 | (type & 1u)));
    REQUIRE(p.direction[1] == uint16_t(Photon::quantise(uv.y) << 1 | ((type >> 1) & 1u)));
  }
}

TEST_CASE("kernels integrate to one over the disc and vanish outside it") {
  for (Kernel k : {Kernel::Uniform, Kernel::Cone, Kernel::Epanechnikov, Kernel::Silverman}) {
    const float r = 0.3f;
    double sum = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {  // ∫ K 2πd dd, midpoint rule
      float d = r * (i + 0.5f) / n;
      sum += kernelWeight(k, d * d, r * r) * 2 * kPi * d * (r / n);
    }
    CHECK(sum == Approx(1.0).epsilon(1e-4));
    CHECK(kernelWeight(k, 1.01f * r * r, r * r) == 0.0f);
  }
}

TEST_CASE("kd-tree k-NN and radius queries agree with brute force - random and planar sets - with the side filter") {
  Rng rng(2, 2);
  for (bool planar : {false, true}) {
    std::vector<Photon> photons;
    for (int i = 0; i < 20000; ++i) {
      Vec3 p(rng.uniform(), planar ? 0.0f : rng.uniform(), rng.uniform());
      Vec3 w = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
      photons.emplace_back(p, w, Spectrum(1.0f), Photon::Type(i % 3));
    }
    PhotonMap map;
    map.build(photons);
    const auto& stored = map.photons();
    for (int q = 0; q < 200; ++q) {
      Vec3 x(rng.uniform(), planar ? 0.0f : rng.uniform(), rng.uniform());
      Vec3 n = q % 2 ? Vec3(0, 1, 0) : Vec3(0.0f);
      uint8_t accept = q % 3 ? Photon::kAcceptAll : Photon::kAcceptIndirect;
      std::vector<std::pair<float, uint32_t>> brute;
      for (uint32_t i = 0; i < stored.size(); ++i) {
        const Photon& p = stored[i];
        if (!((accept >> p.type()) & 1)) continue;
        if (glm::length(n) > 0 && glm::dot(p.wi(), n) <= 0) continue;
        Vec3 d = p.p() - x;
        brute.push_back({glm::dot(d, d), i});
      }
      std::sort(brute.begin(), brute.end());
      std::vector<Neighbour> got;
      map.knn(x, n, accept, 30, 0.0f, &got);
      REQUIRE(got.size() == 30);
      // Same distances in the same order, and each returned photon really is at its distance
      // (indices alone could differ at near-ties: the two sums round differently).
      for (int i = 0; i < 30; ++i) {
        REQUIRE(got[i].d2 == Approx(brute[i].first).epsilon(1e-5).margin(1e-12));
        Vec3 d = stored[got[i].index].p() - x;
        REQUIRE(glm::dot(d, d) == Approx(got[i].d2).epsilon(1e-5).margin(1e-12));
      }
      float r = 0.05f;
      map.withinRadius(x, n, accept, r, &got);
      size_t inside = std::count_if(brute.begin(), brute.end(), [&](auto& b) { return b.first < r * r; });
      REQUIRE(got.size() == inside);
      // k-NN capped by a maximum radius returns exactly those within it when fewer than k.
      map.knn(x, n, accept, 100000, r, &got);
      REQUIRE(got.size() == inside);
    }
  }
}

TEST_CASE("emitted photons' flux sums to the lights' total power") {
  for (const char* name : {"cornell-box.gltf", "glass-caustic.gltf", "furnace.gltf"}) {
    auto scene = loadGltf(scenePath(name));
    const uint64_t N = 100000;
    Spectrum sum(0.0f);
    for (uint64_t i = 0; i < N; ++i) {
      Rng rng(0);
      sum += emitPhoton(*scene, 1, i, N, 0, &rng).flux;
    }
    INFO(name);
    CHECK(sum.r == Approx(scene->totalPower().r).epsilon(0.01));
    CHECK(sum.b == Approx(scene->totalPower().b).epsilon(0.01));
  }
}

TEST_CASE("stored photons: a black sphere around a light absorbs exactly Φ - spread as I(ω) prescribes") {
  // Albedo 0: every photon is stored once, where it first lands (the sphere is centred on the
  // light). Stored flux sums to Φ, and directions from the light follow I(ω).
  for (int kind = 0; kind < 2; ++kind) {
    Scene scene;
    addSphere(scene, 2.0f, lambertian(scene, 0.0f));
    Vec3 axis(0, -1, 0);
    if (kind == 0) scene.addLight(std::make_unique<PointLight>(Vec3(0), PointLight::intensityForPower(Spectrum(10.0f))));
    else scene.addLight(std::make_unique<WarnSpotlight>(Vec3(0), axis, WarnSpotlight::cForPower(Spectrum(10.0f), 5), 5.0f));
    scene.setCamera(Camera{});
    scene.commit();
    PhotonTracingOptions o;
    o.globalPaths = 100000;
    o.causticPaths = 0;
    PhotonMaps maps = tracePhotons(scene, o);
    REQUIRE(maps.global.size() == o.globalPaths);
    double flux = 0;
    std::vector<double> hist(20, 0), expected(20, 0);
    for (const Photon& p : maps.global.photons()) {
      flux += p.flux().g;
      float c = glm::dot(glm::normalize(p.p()), axis);
      hist[std::min(19, int((c + 1) / 2 * 20))] += 1;
    }
    CHECK(flux == Approx(10.0).epsilon(1e-3));
    for (int b = 0; b < 20; ++b) {  // fraction of Φ with cosθ in the bin
      double lo = -1 + b / 10.0, hi = lo + 0.1;
      expected[b] = o.globalPaths * (kind == 0 ? 0.05 : (hi > 0 ? std::pow(hi, 6) - std::pow(std::max(lo, 0.0), 6) : 0.0));
    }
    INFO((kind ? "warn" : "point"));
    CHECK(test::chiSquarePValue(hist, expected) > 1e-3);
  }
}

TEST_CASE("density estimation reproduces E = Φ cosθ / (4πr²) from a point light over a plane") {
  const float h = 1.0f, Phi = 50.0f;
  Scene scene;
  float s = 30.0f;
  addQuad(scene, {-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, lambertian(scene, 0.0f));  // absorbs: direct only
  scene.addLight(std::make_unique<PointLight>(Vec3(0, h, 0), PointLight::intensityForPower(Spectrum(Phi))));
  scene.setCamera(lookingDown(2));
  scene.commit();
  PhotonTracingOptions o;
  o.globalPaths = 2000000;
  o.causticPaths = 0;
  PhotonMaps maps = tracePhotons(scene, o);
  for (Kernel kernel : {Kernel::Uniform, Kernel::Cone, Kernel::Epanechnikov, Kernel::Silverman}) {
    DensityEstimation de;
    de.kernel = kernel;
    de.k = 400;
    for (Vec3 x : {Vec3(0, 0, 0), Vec3(0.5f, 0, 0.2f), Vec3(-1.0f, 0, 0.6f)}) {
      float r2 = h * h + x.x * x.x + x.z * x.z, cosTheta = h / std::sqrt(r2);
      double E = Phi * cosTheta / (4 * kPi * r2);
      INFO("kernel " << int(kernel) << " x=" << x.x);
      // 400 photons: ~5% relative noise at one point; the kernels' smoothing bias is < 1% here.
      CHECK(maps.global.irradiance(x, Vec3(0, 1, 0), de, Photon::kAcceptAll).g == Approx(E).epsilon(0.15));
    }
    // Averaged over many points the noise goes and what remains is the bias.
    double ratio = 0;
    const int n = 200;
    Rng rng(4, 4);
    for (int i = 0; i < n; ++i) {
      Vec3 x(rng.uniform() - 0.5f, 0, rng.uniform() - 0.5f);
      float r2 = h * h + x.x * x.x + x.z * x.z;
      ratio += maps.global.irradiance(x, Vec3(0, 1, 0), de, Photon::kAcceptAll).g / (Phi * h / std::sqrt(r2) / (4 * kPi * r2));
    }
    CHECK(ratio / n == Approx(1.0).epsilon(0.015));
  }
}

TEST_CASE("k-NN with the uniform kernel: k − 1 photons over πr_k² is unbiased - k over πr_k² is not") {
  // Uniform random photons of density D on a plane: the classic k/(πr²) over-estimates by
  // k/(k − 1) (the k-th photon sits on the boundary); photonlab's estimator does not.
  Rng rng(5, 5);
  const int N = 200000;
  std::vector<Photon> photons;
  for (int i = 0; i < N; ++i)
    photons.emplace_back(Vec3(rng.uniform(), 0, rng.uniform()), Vec3(0, 1, 0), Spectrum(1.0f), Photon::kDirect);
  PhotonMap map;
  map.build(photons);
  DensityEstimation de;
  de.kernel = Kernel::Uniform;
  de.k = 8;
  double ours = 0, classic = 0;
  const int queries = 4000;
  for (int q = 0; q < queries; ++q) {
    Vec3 x(0.1f + 0.8f * rng.uniform(), 0, 0.1f + 0.8f * rng.uniform());
    GatherStats st;
    ours += map.irradiance(x, Vec3(0, 1, 0), de, Photon::kAcceptAll, &st).g;
    classic += de.k / (kPi * st.radius * st.radius);
  }
  CHECK(ours / queries == Approx(N).epsilon(0.02));
  CHECK(classic / queries > 1.1 * N);  // 8/7 = 1.14
}

TEST_CASE("photons arriving at the back side are neither counted nor shrink the radius") {
  std::vector<Photon> photons;
  Rng rng(6, 6);
  for (int i = 0; i < 1000; ++i)  // all arrive from above (wi.y > 0) at y = 0
    photons.emplace_back(Vec3(rng.uniform() - 0.5f, 0, rng.uniform() - 0.5f), glm::normalize(Vec3(0.1f, 1, 0)),
                         Spectrum(1.0f), Photon::kIndirect);
  PhotonMap map;
  map.build(photons);
  DensityEstimation de;
  GatherStats below, above;
  CHECK(isBlack(map.irradiance(Vec3(0), Vec3(0, -1, 0), de, Photon::kAcceptAll, &below)));
  CHECK(below.photons == 0);
  CHECK(average(map.irradiance(Vec3(0), Vec3(0, 1, 0), de, Photon::kAcceptAll, &above)) > 0);
  CHECK(above.photons == de.k);
}

TEST_CASE("mirror caustic: the floor under a point light receives E = I/h² + R·I/(2H − h)²") {
  // Floor at y = 0, point light at h, a horizontal mirror of reflectance R at H facing down.
  // Direct photons give I/h²; the caustic map (L S D) gives the mirror-image light at height
  // 2H − h. A path tracer cannot sample the second term: nothing can hit a point light.
  const float h = 0.5f, H = 1.0f, I = 4.0f, R = 0.8f, s = 20.0f;
  Scene scene;
  addQuad(scene, {-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, lambertian(scene, 0.5f));
  uint32_t mirror = scene.addMaterial({"mirror", std::make_unique<Mirror>(ColorTexture(Spectrum(R))), Spectrum(0), false});
  addQuad(scene, {-s, H, -s}, {s, H, -s}, {s, H, s}, {-s, H, s}, mirror);
  scene.addLight(std::make_unique<PointLight>(Vec3(0, h, 0), Spectrum(I)));
  scene.setCamera(lookingDown(0.9f));
  scene.commit();
  PhotonTracingOptions o;
  o.globalPaths = 1000000;
  o.causticPaths = 1000000;
  PhotonMaps maps = tracePhotons(scene, o);
  DensityEstimation de;
  de.k = 1000;
  Vec3 x(0), up(0, 1, 0);
  double direct = maps.global.irradiance(x, up, de, 1 << Photon::kDirect).g;
  double caustic = maps.caustic.irradiance(x, up, de, Photon::kAcceptAll).g;
  CHECK(direct == Approx(I / (h * h)).epsilon(0.06));
  CHECK(caustic == Approx(R * I / ((2 * H - h) * (2 * H - h))).epsilon(0.06));
  // The global map's caustic photons estimate the same term from their own emission.
  CHECK(maps.global.irradiance(x, up, de, Photon::kAcceptCaustic).g == Approx(caustic).epsilon(0.1));
}

TEST_CASE("photon mapping in the closed furnace: L = Le / (1 − ρ) with and without final gathering") {
  auto scene = loadGltf(scenePath("furnace.gltf"));
  for (int fg : {0, 8}) {
    PhotonOptions io;
    io.photons = 400000;
    io.causticPhotons = 0;
    io.finalGather = fg;
    io.density.k = 100;
    PhotonIntegrator pm(io);
    RenderOptions ro;
    ro.width = ro.height = 12;
    ro.spp = 8;
    INFO("final gather " << fg);
    CHECK(mean(render(*scene, pm, ro, nullptr)) == Approx(2.0).epsilon(0.02));
  }
}

TEST_CASE("Cornell box: photon mapping with final gathering agrees with the path tracer region by region", "[long]") {
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  RenderOptions ro;
  ro.width = ro.height = 32;
  ro.spp = 2048;
  auto path = makeIntegrator("path", {});
  ImageRGB reference = render(*scene, *path, ro, nullptr);
  PhotonOptions io;
  io.photons = 500000;
  io.finalGather = 64;
  PhotonIntegrator pm(io);
  ro.spp = 8;
  ImageRGB img = render(*scene, pm, ro, nullptr);
  // Pixels that see the light (Le = 17) are the same emission in both images, but at 8 spp
  // their partial coverage is noise that would swamp the comparison: leave them out.
  auto seesLight = [&](int x, int y) {
    for (float dx : {0.0f, 1.0f})
      for (float dy : {0.0f, 1.0f}) {
        SurfaceHit hit;
        if (scene->intersect(scene->camera().generateRay(x + dx, y + dy, 32, 32), &hit) && hit.light) return true;
      }
    return false;
  };
  // 4×4 regions of 8×8 pixels; each region's mean within the tolerance of the reference.
  double all = 0, allRef = 0;
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 4; ++bx) {
      double a = 0, b = 0;
      for (int y = 8 * by; y < 8 * by + 8; ++y)
        for (int x = 8 * bx; x < 8 * bx + 8; ++x) {
          if (seesLight(x, y)) continue;
          a += average(img.at(x, y));
          b += average(reference.at(x, y));
        }
      all += a, allRef += b;
      INFO("region " << bx << "," << by);
      CHECK(a / b == Approx(1.0).epsilon(0.05));
    }
  CHECK(all / allRef == Approx(1.0).epsilon(0.02));
}

TEST_CASE("photon mapping: no diffuse surface or no power renders zeros with a warning - never hangs") {
  // Only a mirror box around a point light: photons bounce until Russian roulette or max depth.
  Scene scene;
  uint32_t mirror = scene.addMaterial({"mirror", std::make_unique<Mirror>(ColorTexture(Spectrum(1.0f))), Spectrum(0), false});
  addSphere(scene, 2.0f, mirror);
  scene.addLight(std::make_unique<PointLight>(Vec3(0), Spectrum(1.0f)));
  scene.setCamera(Camera{});
  scene.commit();
  PhotonOptions io;
  io.photons = 20000;
  io.causticPhotons = 20000;
  PhotonIntegrator pm(io);
  RenderOptions ro;
  ro.width = ro.height = 8;
  ro.spp = 1;
  CHECK(mean(render(scene, pm, ro, nullptr)) == 0.0);
  CHECK(pm.warnings().size() == 1);
  // A light of zero power.
  Scene dark;
  addQuad(dark, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, lambertian(dark, 0.5f));
  dark.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(0.0f)));
  dark.setCamera(lookingDown(2));
  dark.commit();
  PhotonIntegrator pm2(io);
  CHECK(mean(render(dark, pm2, ro, nullptr)) == 0.0);
  CHECK(pm2.warnings().size() == 1);
}

TEST_CASE("photon mapping is bit-identical whatever the thread count") {
  auto scene = loadGltf(scenePath("cornell-spheres.gltf"));
  PhotonOptions io;
  io.photons = 50000;
  io.causticPhotons = 50000;
  io.finalGather = 4;
  RenderOptions ro;
  ro.width = ro.height = 16;
  ro.spp = 2;
  std::vector<float> images[2];
  for (int t : {1, 2}) {
    PhotonIntegrator pm(io);
    ro.threads = t;
    images[t - 1] = render(*scene, pm, ro, nullptr).data;
  }
  CHECK(images[0] == images[1]);
}

TEST_CASE("debug images: photon count and gather radius") {
  auto scene = loadGltf(scenePath("cornell-box.gltf"));
  PhotonOptions io;
  io.photons = 100000;
  io.density.k = 20;
  io.aov = "photons";
  RenderOptions ro;
  ro.width = ro.height = 8;
  ro.spp = 1;
  PhotonIntegrator count(io);
  ImageRGB c = render(*scene, count, ro, nullptr);
  // Epanechnikov: all k photons weigh in, fewer only where the maximum radius cuts the
  // search short. Corner pixels see past the box: no estimate.
  int full = 0;
  for (float v : c.data) {
    REQUIRE((v >= 0.0f && v <= 20.0f && v == std::floor(v)));
    full += v == 20.0f;
  }
  CHECK(c.at(4, 4).g == 20.0f);
  CHECK(full > 32);
  io.aov = "radius";
  PhotonIntegrator radius(io);
  ImageRGB r = render(*scene, radius, ro, nullptr);
  float maxRadius = 0.05f * scene->bounds().radius();  // the default cap
  for (float v : r.data) REQUIRE((v >= 0.0f && v <= maxRadius * 1.0001f));
  CHECK(r.at(4, 4).g > 0.0f);
  CHECK(r.at(4, 4).g < maxRadius);
}

TEST_CASE("targeted emission: the flux through a disc is E·cosθ·area inside the target and outside it - the sun and a constant sky") {
  // A 1 m plate at the origin and a 20 m floor 20 m below: the scene's sphere has R ≈ 17.3 m,
  // the target is the unit sphere at the origin, q = 1/2. Half the photons start on the target's
  // disc (a density ~150× the scene disc's), the rest on the scene's; each carries
  // Φ/(pick·N)·p_uniform/p_mixture. The flux crossing the plane y = 0 downwards through a disc
  // must be E·|cosθ|·A for the sun and π·L·A for the sky, through a disc inside the target
  // (D1: r = 0.5 m at the origin) as through one the target does not reach (D2: r = 2 m at
  // x = 8 m, where only the uniform half lands, at twice the weight). Each sum is checked
  // within 4 of its standard errors, computed from the photons' contributions.
  const float E = 2.0f, L = 0.7f;
  const Vec3 w = glm::normalize(Vec3(0.3f, -1.0f, 0.2f));
  for (int sky = 0; sky < 2; ++sky) {
    Scene scene;
    addQuad(scene, {-0.5f, 0, -0.5f}, {-0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, 0, -0.5f}, lambertian(scene, 0.5f));
    addQuad(scene, {-10, -20, -10}, {-10, -20, 10}, {10, -20, 10}, {10, -20, -10}, lambertian(scene, 0.5f));
    if (sky) scene.addLight(EnvironmentLight::constant(Spectrum(L)));
    else scene.addLight(std::make_unique<DirectionalLight>(w, Spectrum(E)));
    scene.commit();
    INFO((sky ? "constant sky" : "sun") << ", scene radius " << scene.bounds().radius());
    EmissionTarget target;
    target.center = Vec3(0.0f);
    target.radius = 1.0f;
    struct Disc {
      Vec3 centre;
      float radius;
      double sum = 0, sum2 = 0;
    };
    Disc discs[2] = {{Vec3(0.0f), 0.5f}, {Vec3(8, 0, 0), 2.0f}};
    const uint64_t N = 400000;
    for (uint64_t i = 0; i < N; ++i) {
      Rng rng(0);
      EmittedRay e = emitPhoton(scene, 7, i, N, 0, &rng, false, nullptr, &target);
      if (!(e.ray.d.y < 0)) continue;
      const Vec3 p = e.ray.o + (-e.ray.o.y / e.ray.d.y) * e.ray.d;
      for (Disc& d : discs)
        if (glm::length(p - d.centre) < d.radius) d.sum += e.flux.g, d.sum2 += double(e.flux.g) * e.flux.g;
    }
    for (const Disc& d : discs) {
      const double area = kPi * d.radius * d.radius;
      const double expected = sky ? kPi * L * area : E * std::abs(w.y) * area;
      const double se = std::sqrt(std::max(d.sum2 - d.sum * d.sum / N, 0.0));  // √(N·Var) of the sum
      INFO("disc at x = " << d.centre.x << ": " << d.sum << " against " << expected << " (standard error " << se << ")");
      CHECK(se < 0.05 * expected);
      CHECK(std::abs(d.sum - expected) < 4 * se);
    }
  }
}

TEST_CASE("stored path types: a map that skips direct photons holds exactly the full map's caustic and indirect ones") {
  // sppm and pppm store only what they gather; the paths and their draws must not change, so
  // the smaller map is the full one without its direct photons, photon for photon.
  auto scene = loadGltf(scenePath("glass-caustic.gltf"));
  PhotonTracingOptions o;
  o.globalPaths = 20000;
  o.causticPaths = 0;
  PhotonMaps all = tracePhotons(*scene, o);
  o.store = Photon::kAcceptIndirect | Photon::kAcceptCaustic;
  PhotonMaps some = tracePhotons(*scene, o);
  REQUIRE(all.global.count(Photon::kAcceptDirect) > 0);
  REQUIRE(all.global.count(o.store) > 0);
  CHECK(some.global.count(Photon::kAcceptDirect) == 0);
  CHECK(some.global.size() == all.global.count(o.store));
  auto key = [](const Photon& p) { return std::make_tuple(p.position[0], p.position[1], p.position[2], p.type()); };
  std::vector<std::tuple<float, float, float, Photon::Type>> a, b;
  for (const Photon& p : all.global.photons())
    if ((o.store >> p.type()) & 1) a.push_back(key(p));
  for (const Photon& p : some.global.photons()) b.push_back(key(p));
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  CHECK(a == b);
}

TEST_CASE("adaptive photon tracing: a ball on a floor under the sun - the visible fraction r²/R², every photon in the ball, E there uniformly") {
  // A 20 m floor lit straight down by the sun (E = 2): uniform paths start on the scene's disc
  // (R = 10√2 m) and land uniformly over it, so the paths visible to a ball of r = 0.5 m at the
  // origin are V_c = r²/R² of them (maxDepth 0: one photon per path). The chain's map holds
  // only visible paths, scaled by V̂_c·N/N_chain: its irradiance in the ball is E·V̂_c/V_c, so
  // E·V̂_c/V_c·(V_c/V̂_c) must be E wherever it is measured in the ball. Eight seeds give the
  // standard errors (5 of them: Student's t with 7 degrees of freedom passes that 0.2% of the
  // time); V̂_c's is √(V_c(1 − V_c)/N) per seed.
  const float E = 2.0f, r = 0.5f;
  Scene scene;
  addQuad(scene, {-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, lambertian(scene, 0.5f));
  scene.addLight(std::make_unique<DirectionalLight>(Vec3(0, -1, 0), Spectrum(E)));
  scene.commit();
  const double R = scene.bounds().radius(), Vc = double(r) * r / (R * R);
  PhotonVisibility visibility({{Vec3(0.0f), r * r}});
  const uint64_t N = 500000;
  const Vec3 points[3] = {Vec3(0.0f), Vec3(0.3f, 0, 0), Vec3(-0.2f, 0, 0.25f)};
  std::vector<double> fraction, normalised[3];
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    PhotonTracingOptions o;
    o.globalPaths = N;
    o.causticPaths = 0;
    o.maxDepth = 0;
    o.seed = seed;
    o.adaptive = &visibility;
    o.mutationSize = 0.01f;  // the ball spans ~r/R = 0.035 of the disc's coordinates
    PhotonMaps maps = tracePhotons(scene, o);
    const AdaptiveChainStats& c = maps.chain;
    REQUIRE(c.uniform == N);
    INFO("seed " << seed << ": " << c.visible << " visible of " << c.uniform << ", " << c.samples << " chain samples, "
                 << c.accepted << " of " << c.mutations << " mutations accepted");
    // The chains mutate, and each found a state early: the first visible one of ~1/V_c = 800
    // draws, in chains of 4096.
    CHECK(c.accepted > 0);
    CHECK(c.accepted < c.mutations);
    CHECK(c.samples > N * 3 / 4);
    double farthest = 0;
    for (const Photon& ph : maps.global.photons()) farthest = std::max(farthest, double(glm::length(ph.p())));
    CHECK(farthest <= r * 1.0001);
    fraction.push_back(c.visibleFraction());
    DensityEstimation de;
    de.kernel = Kernel::Uniform;
    de.radius = 0.1f;
    for (int k = 0; k < 3; ++k)
      normalised[k].push_back(maps.global.irradiance(points[k], Vec3(0, 1, 0), de, Photon::kAcceptAll).g * Vc / c.visibleFraction());
  }
  auto meanAndError = [](const std::vector<double>& v) {
    double m = 0, s2 = 0;
    for (double x : v) m += x / v.size();
    for (double x : v) s2 += (x - m) * (x - m) / (v.size() - 1);
    return std::make_pair(m, std::sqrt(s2 / v.size()));
  };
  const double vcError = std::sqrt(Vc * (1 - Vc) / N / 8);
  auto [vcMean, vcSpread] = meanAndError(fraction);
  INFO("V̂_c " << vcMean << " against " << Vc << " (standard error " << vcError << ", seeds' " << vcSpread << ")");
  CHECK(std::abs(vcMean - Vc) < 4 * vcError);
  for (int k = 0; k < 3; ++k) {
    auto [m, se] = meanAndError(normalised[k]);
    INFO("E at (" << points[k].x << ", " << points[k].z << "): " << m << " against " << E << ", standard error " << se);
    CHECK(se < 0.02 * E);
    CHECK(std::abs(m - E) < 5 * se);
  }
}

TEST_CASE("targeted emission from an area light: the flux through a disc is ∫E dA inside the target and outside it, with a fraction of the noise inside") {
  // A 6 m square Lambertian emitter (L = 1) 3 m above the plane y = 0, facing down; the target
  // is the unit sphere at the origin, q = 1/2. Half the photons leave in the cone from their
  // point on the light around the sphere, the rest cosine-distributed; each carries
  // Φ/(pick·N)·p_light(ω)/p_mixture(ω). The flux crossing y = 0 through a disc must be
  // ∫ E dA, E(x) = L ∫ h²/|y − x|⁴ dA_y (cosθ = cosθ' = h/|y − x|), by a midpoint rule over
  // the light and the disc: through a disc inside the target (r = 0.5 m at the origin) and
  // one outside it (r = 1 m at x = 4 m), each within 4 standard errors. Inside, the standard
  // error must be below half the untargeted one.
  const float h = 3.0f, half = 3.0f;
  Scene scene;
  uint32_t light = scene.addMaterial({"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(1.0f), false});
  addQuad(scene, {-half, h, -half}, {half, h, -half}, {half, h, half}, {-half, h, half}, light);
  scene.commit();
  EmissionTarget target;
  target.center = Vec3(0.0f);
  target.radius = 1.0f;
  target.areaLights = true;
  struct Disc {
    Vec3 centre;
    float radius;
    double sum[2] = {0, 0}, sum2[2] = {0, 0};  // untargeted, targeted
  };
  Disc discs[2] = {{Vec3(0.0f), 0.5f}, {Vec3(4, 0, 0), 1.0f}};
  auto expectedFlux = [&](const Disc& d) {
    const int nl = 120, nr = 10, na = 24;
    double flux = 0;
    for (int ir = 0; ir < nr; ++ir)
      for (int ia = 0; ia < na; ++ia) {
        const double rr = d.radius * (ir + 0.5) / nr, a = 2 * kPi * (ia + 0.5) / na;
        const double x = d.centre.x + rr * std::cos(a), z = d.centre.z + rr * std::sin(a);
        const double dA = d.radius * d.radius / nr * (ir + 0.5) / nr * 2 * kPi / na;  // r dr dφ
        double E = 0;
        for (int i = 0; i < nl; ++i)
          for (int j = 0; j < nl; ++j) {
            const double lx = -half + 2 * half * (i + 0.5) / nl, lz = -half + 2 * half * (j + 0.5) / nl;
            const double r2 = (lx - x) * (lx - x) + (lz - z) * (lz - z) + double(h) * h;
            E += double(h) * h / (r2 * r2);
          }
        flux += E * (2 * half / nl) * (2 * half / nl) * dA;
      }
    return flux;  // L = 1
  };
  const uint64_t N = 400000;
  for (int aimed = 0; aimed < 2; ++aimed)
    for (uint64_t i = 0; i < N; ++i) {
      Rng rng(0);
      EmittedRay e = emitPhoton(scene, 7, i, N, 0, &rng, false, nullptr, aimed ? &target : nullptr);
      if (!(e.ray.d.y < 0)) continue;
      const Vec3 p = e.ray.o + (-e.ray.o.y / e.ray.d.y) * e.ray.d;
      for (Disc& d : discs)
        if (glm::length(p - d.centre) < d.radius) d.sum[aimed] += e.flux.g, d.sum2[aimed] += double(e.flux.g) * e.flux.g;
    }
  double se[2][2];
  for (int k = 0; k < 2; ++k)
    for (int aimed = 0; aimed < 2; ++aimed) {
      const Disc& d = discs[k];
      const double expected = expectedFlux(d);
      se[k][aimed] = std::sqrt(std::max(d.sum2[aimed] - d.sum[aimed] * d.sum[aimed] / N, 0.0));
      INFO("disc at x = " << d.centre.x << (aimed ? ", aimed" : ", not aimed") << ": " << d.sum[aimed] << " against " << expected
                          << " (standard error " << se[k][aimed] << ")");
      CHECK(se[k][aimed] < 0.05 * expected);
      CHECK(std::abs(d.sum[aimed] - expected) < 4 * se[k][aimed]);
    }
  INFO("inside the target: standard error " << se[0][1] << " aimed, " << se[0][0] << " not");
  CHECK(se[0][1] < 0.5 * se[0][0]);
}
