// Hardening: inputs found by fuzzing, truncated files, impossible sizes, degenerate geometry,
// and non-finite samples. None of them may crash, hang, exhaust memory or put NaN on the film.
#include <catch2/catch.hpp>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "gltf_fixture.h"
#include "render/integrator.h"
#include "lights/point_light.h"
#include "photon/photon_tracer.h"
#include "integrators/progressive.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// Loads `path`; returns "" when it loads (and then renders finite 4×4 images with the path
// tracer and the photon mapper), or the Error's message.
std::string loadAndRender(const std::string& path) {
  std::unique_ptr<Scene> scene;
  try {
    scene = loadGltf(path);
  } catch (const Error& e) {
    return e.what();
  }
  RenderOptions o;
  o.width = o.height = 4;
  o.spp = 1;
  const std::map<std::string, double> io = {{"photons", 64}, {"caustic_photons", 64}};
  for (const char* name : {"path", "photon"}) {
    auto integrator = makeWith(name, io);
    ImageRGB image = render(*scene, *integrator, o, nullptr);
    for (float v : image.data) REQUIRE(std::isfinite(v));
  }
  return "";
}

std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// A BSDF whose every value is NaN: a stand-in for a buggy or numerically broken material.
class NaNBSDF : public BSDF {
 public:
  NaNBSDF() : BSDF(kDiffuseReflection) {}
  Spectrum eval(const Vec3&, const Vec3&, const BSDFContext&) const override { return Spectrum(NAN); }
  float pdf(const Vec3&, const Vec3&, const BSDFContext&) const override { return NAN; }
  bool sample(const Vec3&, const BSDFContext&, const Vec2& u, float, BSDFSample* s) const override {
    s->wi = Vec3(0, 0, 1);
    s->weight = Spectrum(NAN);
    s->pdf = NAN;
    return true;
  }
  const char* name() const override { return "nan"; }
};

}  // namespace

TEST_CASE("robustness: every input the fuzzers found loads or fails with one line naming the file") {
  int count = 0;
  for (auto& e : fs::directory_iterator(std::string(PHOTONLAB_SOURCE_DIR) + "/tests/fuzz/regressions")) {
    const std::string path = e.path().string();
    if (e.path().extension() != ".gltf" && e.path().extension() != ".glb") continue;
    INFO(path);
    std::string error = loadAndRender(path);
    if (!error.empty()) {
      CHECK_THAT(error, Contains(path));
      CHECK(error.find('\n') == std::string::npos);
    }
    ++count;
  }
  CHECK(count >= 1);
}

TEST_CASE("robustness: a GLB cut short anywhere is an Error naming the file") {
  GltfFixture f;
  const std::string whole = readBytes(f.writeGlb("whole.glb"));
  REQUIRE(loadAndRender(GltfFixture::dir() + "/whole.glb").empty());
  const std::string cut = GltfFixture::dir() + "/cut.glb";
  for (size_t n = 0; n < whole.size(); n += 5) {
    std::ofstream(cut, std::ios::binary | std::ios::trunc).write(whole.data(), std::streamsize(n));
    INFO("first " << n << " of " << whole.size() << " bytes");
    std::string error = loadAndRender(cut);
    CHECK_THAT(error, Contains(cut));
  }
}

TEST_CASE("robustness: rays Embree would reject are misses - never an abort") {
  GltfFixture f;
  auto scene = loadGltf(f.write("rays.gltf"));
  SurfaceHit hit;
  REQUIRE(scene->intersect(Ray{Vec3(0, 1, 0), Vec3(0, -1, 0)}, &hit));  // the floor, for contrast
  for (Ray r : {Ray{Vec3(1e30f, 1, 0), Vec3(0, -1, 0)}, Ray{Vec3(0, 1, 0), Vec3(NAN, -1, 0)},
                Ray{Vec3(0, 1, 0), Vec3(0, -1, 0), NAN}, Ray{Vec3(0, 1, 0), Vec3(0, -INFINITY, 0)}}) {
    CHECK_FALSE(scene->intersect(r, &hit));
    CHECK(scene->occluded(r));
  }
}

TEST_CASE("robustness: scene coordinates beyond 1e7 m are an Error - not an abort in Embree") {
  GltfFixture f;
  f.doc["nodes"][0]["translation"] = {0, 0, 1e30};
  CHECK_THAT(loadAndRender(f.write("far-node.gltf")), Contains("nodes[0]: transform places it beyond 1e7 m"));
  GltfFixture g;
  g.doc["nodes"][0]["scale"] = {1e20, 1, 1};
  CHECK_THAT(loadAndRender(g.write("far-vertex.gltf")), Contains("POSITION: vertex 0 lies beyond 1e7 m"));
}

TEST_CASE("robustness: a texture claiming 100000x100000 pixels is refused before it is decoded") {
  // A PNG signature and IHDR chunk only: the header is all stb_image would need to allocate 40 GB.
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                              0, 1, 0x86, 0xA0, 0, 1, 0x86, 0xA0, 8, 2, 0, 0, 0, 0, 0, 0, 0};
  GltfFixture f;
  f.doc["images"] = {{{"uri", "data:image/png;base64," + base64(png)}}};
  f.doc["textures"] = {{{"source", 0}}};
  f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  std::string error = loadAndRender(f.write("huge-texture.gltf"));
  CHECK_THAT(error, Contains("images[0]: 100000 x 100000 pixels"));
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  CHECK(usage.ru_maxrss < 1024 * 1024);  // KiB
}

TEST_CASE("robustness: photon counts and resolutions beyond the available memory are refused up front") {
  GltfFixture f;
  auto scene = loadGltf(f.write("memory.gltf"));
  PhotonTracingOptions t;
  t.globalPaths = 4000000000ull;  // 96 GB of photons and index
  t.causticPaths = 0;
  ::setenv("PHOTONLAB_MEMORY_LIMIT", "1000000000", 1);  // and pretend 1 GB is free
  CHECK_THROWS_WITH(tracePhotons(*scene, t), Contains("4000000000 photon paths: needs"));
  RenderOptions o;
  o.width = 20000;
  o.height = 20000;  // 400 M pixels × 40 bytes
  auto path = makeIntegrator("path");
  CHECK_THROWS_WITH(render(*scene, *path, o, nullptr), Contains("20000x20000 image: needs"));
  ProgressiveOptions po;
  CHECK_THROWS_WITH(PassSetup(*scene, o, po), Contains("20000x20000 progressive image: needs"));
  ::unsetenv("PHOTONLAB_MEMORY_LIMIT");
}

TEST_CASE("robustness: degenerate triangles - coincident vertices - a zero-area light - a zero-power light") {
  Scene scene;
  uint32_t floor = lambertian(scene, 0.5f);
  addQuad(scene, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, floor);
  // Degenerate: collinear, and all three vertices at one point.
  scene.addMesh({{0, 0.5f, 0}, {0.1f, 0.5f, 0}, {0.2f, 0.5f, 0}}, {}, {}, {0, 1, 2}, floor);
  scene.addMesh({{0, 0.3f, 0}, {0, 0.3f, 0}, {0, 0.3f, 0}}, {}, {}, {0, 1, 2}, floor);
  // An emissive triangle of zero area is not a light (it could never be sampled).
  uint32_t emitter = scene.addMaterial({"emitter", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.5f))), Spectrum(10), false});
  scene.addMesh({{0, 0.8f, 0}, {0, 0.8f, 0}, {0.1f, 0.8f, 0}}, {}, {}, {0, 1, 2}, emitter);
  scene.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(1.0f)));
  scene.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0.5f), Spectrum(0.0f)));  // zero power
  scene.setCamera(lookingDown(2.0f));
  scene.commit();
  CHECK(scene.lights().size() == 2);  // the two point lights; no area light from the zero-area triangle
  RenderOptions o;
  o.width = o.height = 16;
  o.spp = 4;
  const std::map<std::string, double> io = {{"photons", 2000}, {"caustic_photons", 2000}};
  for (const char* name : {"direct", "path", "photon"}) {
    auto integrator = makeWith(name, io);
    RenderInfo stats;
    ImageRGB image = render(scene, *integrator, o, &stats);
    INFO(name);
    CHECK(stats.nonFiniteSamples == 0);
    double sum = 0;
    for (float v : image.data) {
      REQUIRE(std::isfinite(v));
      sum += v;
    }
    CHECK(sum > 0);
  }
}

TEST_CASE("robustness: a NaN-producing material is discarded - counted - and shown by the nan AOV") {
  Scene scene;
  uint32_t good = lambertian(scene, 0.5f);
  uint32_t bad = scene.addMaterial({"nan", std::make_unique<NaNBSDF>(), Spectrum(0), false});
  addQuad(scene, {-1, 0, -1}, {-1, 0, 1}, {0, 0, 1}, {0, 0, -1}, bad);  // x < 0: image left half
  addQuad(scene, {0, 0, -1}, {0, 0, 1}, {1, 0, 1}, {1, 0, -1}, good);
  scene.addLight(std::make_unique<PointLight>(Vec3(0, 1, 0), Spectrum(1.0f)));
  scene.setCamera(lookingDown(1.0f, 1.5f));
  scene.commit();
  const int W = 16, H = 16;
  RenderOptions o;
  o.width = W;
  o.height = H;
  o.spp = 2;
  auto path = makeIntegrator("path");
  RenderInfo stats;
  ImageRGB image = render(scene, *path, o, &stats);
  for (float v : image.data) REQUIRE(std::isfinite(v));
  CHECK(stats.nonFiniteSamples > 0);

  o.nanAov = true;
  RenderInfo aovStats;
  ImageRGB nan = render(scene, *path, o, &aovStats);
  CHECK(aovStats.nonFiniteSamples == stats.nonFiniteSamples);
  double total = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      float f = nan.at(x, y).r;
      total += f * o.spp;
      if (x >= W / 2 + 1) CHECK(f == 0.0f);  // the good half: no sample discarded
      if (x < W / 2 - 1) CHECK(f == 1.0f);   // the NaN half: every sample discarded
    }
  CHECK(total == double(stats.nonFiniteSamples));

  // Photons and progressive estimates never carry the NaN either.
  for (const char* name : {"photon"}) {
    auto pm = makeWith(name, {{"photons", 5000}, {"caustic_photons", 5000}});
    o.nanAov = false;
    ImageRGB img = render(scene, *pm, o, nullptr);
    for (float v : img.data) REQUIRE(std::isfinite(v));
  }
  for (const char* name : {"ppm", "sppm", "pppm"}) {
    RenderInfo info;
    ImageRGB img = makeWith(name, {{"passes", 2}, {"photons_per_pass", 5000}})->render(scene, o, &info);
    INFO(name);
    for (float v : img.data) REQUIRE(std::isfinite(v));
  }
}
