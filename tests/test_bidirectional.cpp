// Bidirectional path tracing, bidirectional photon mapping and vertex connection and merging
// (integrators/bidirectional.cpp). Expected values come from closed forms (the furnace, the
// mirror caustic) or from the path tracer, an independent estimator; tolerances from the seeds'
// own noise (two seeds, their differences estimate each pixel's or region's variance).
#include <catch2/catch.hpp>

#include <cmath>

#include "bsdfs/ggx_conductor.h"
#include "bsdfs/metallic_roughness.h"
#include "bsdfs/phong.h"
#include "integrator_helpers.h"
#include "integrators/bidirectional.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

const char* const kBidirectional[] = {"bdpt", "vcm", "bpm"};

ImageRGB renderWith(const Scene& scene, const std::string& name, int W, int H, int spp, uint64_t seed,
                    std::map<std::string, double> values = {}, int threads = 0, bool spectral = false,
                    std::vector<NamedImage>* extras = nullptr, const std::map<std::string, std::string>& choices = {}) {
  RenderOptions ro;
  ro.width = W;
  ro.height = H;
  ro.spp = spp;
  ro.seed = seed;
  ro.threads = threads;
  ro.spectral = spectral;
  values["spp"] = spp;
  auto integrator = makeWith(name, values, ro, choices);
  ImageRGB image = integrator->render(scene, ro, nullptr);
  if (extras) *extras = integrator->extraImages();
  return image;
}

std::unique_ptr<Scene> sceneFile(const char* name) {
  return loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name + ".gltf");
}

}  // namespace

TEST_CASE("bidirectional: the closed furnace converges to L = Le/(1 − ρ) = 2 with bdpt, vcm and bpm - in RGB and spectral", "[heavy]") {
  // scenes/furnace.gltf: emissive diffuse walls, Le = 1, ρ = 0.5, camera inside; every pixel's
  // expectation is 2 (the geometric series). 16×16 pixels, 64 iterations, seeds 1 and 2;
  // max_depth 64, so the series' cut-off (2⁻⁶⁵) is far below the noise. The mean within 1%, as
  // the other integrators' furnace tests; then no structure beyond noise: the pixels' spread
  // around 2 over the seeds' noise (variance mean(d²)/2 from their differences d) within
  // [0.7, 1.4] (768 values: its standard error ~5%). Merging's bias is zero here: the radiance
  // is the same everywhere.
  // Both heuristics, and the Sobol' sampler (its points are uniform one by one, so the
  // expectation is the same; the seeds' independence, which the spread check needs, too).
  auto scene = sceneFile("furnace");
  for (const auto& [heuristic, sampler] : {std::pair{"power", "independent"}, {"balance", "independent"}, {"power", "sobol"}})
    for (const char* name : kBidirectional) {
      INFO(name << ", " << heuristic << " heuristic, " << sampler << " sampler");
      const std::map<std::string, std::string> choices{{"heuristic", heuristic}, {"sampler", sampler}};
      ImageRGB a = renderWith(*scene, name, 16, 16, 64, 1, {{"max_depth", 64}, {"radius", 0.05}}, 0, false, nullptr, choices);
      ImageRGB b = renderWith(*scene, name, 16, 16, 64, 2, {{"max_depth", 64}, {"radius", 0.05}}, 0, false, nullptr, choices);
      checkFurnace(a, b);
    }
  // Spectral: white light, so the luminance is 2. With merging, every path of an iteration
  // shares its three wavelengths (a merge joins paths of different pixels; the iterations' sets
  // are stratified), so the image mean's noise is that of its iterations' wavelength samples,
  // not of its pixels'. Hence 12 seeds of 16×16 pixels × 64 iterations, and the mean's standard
  // error from the seeds' spread: the luminance within 4 standard errors of 2, and that error
  // below 0.75% (the test sees a 3% error; measured 0.4%, 0.1% for bdpt).
  for (const char* name : kBidirectional) {
    INFO(name << " spectral");
    std::vector<double> means;
    const int seeds = 12;
    for (uint64_t seed = 1; seed <= seeds; ++seed) {
      ImageRGB a = renderWith(*scene, name, 16, 16, 64, seed, {{"max_depth", 64}, {"radius", 0.05}}, 0, true);
      double l = 0;
      for (int i = 0; i < 256; ++i) l += luminance(a.at(i % 16, i / 16));
      means.push_back(l / 256);
    }
    double mean = 0, var = 0;
    for (double m : means) mean += m / seeds;
    for (double m : means) var += (m - mean) * (m - mean) / (seeds - 1);
    const double se = std::sqrt(var / seeds);
    INFO("luminance " << mean << " ± " << se);
    CHECK(std::abs(mean - 2.0) < 4 * se);
    CHECK(se < 0.015);
  }
}

TEST_CASE("bidirectional: the mirror caustic of a point light per pixel - E = I/h² + R·I/(2H − h)² - where the path tracer fails", "[heavy]") {
  // scene_helpers' MirrorCaustic: the mirror-image term is reachable only from the light side:
  // light tracing (t = 1) in bdpt, merging too in vcm and bpm. 512 iterations; merge radius
  // 2 cm, about two pixels' footprint, where the closed form's curvature biases a disc average
  // by ~0.1%. Acceptance as the light tracer's test (checkMirrorCaustic). With either MIS
  // heuristic: the weights must sum to 1 over the techniques for β = 1 as for β = 2. With the
  // Sobol' sampler too: stratified draws must not shift any pixel's expectation.
  for (const auto& [heuristic, sampler] : {std::pair{"power", "independent"}, {"balance", "independent"}, {"power", "sobol"}})
    for (const char* name : kBidirectional) {
      INFO(name << ", " << heuristic << " heuristic, " << sampler << " sampler");
      checkMirrorCaustic([&](const Scene& scene, int W, uint64_t seed) {
        return renderWith(scene, name, W, W, 512, seed, {{"radius", 0.02}}, 0, false, nullptr,
                          {{"heuristic", heuristic}, {"sampler", sampler}});
      });
    }
}

TEST_CASE("bdpt: the weighted techniques' images sum to the image - and asking for them changes nothing") {
  // --aov strategies: one image per technique (s, t) of every depth up to max_depth, each its
  // MIS-weighted share. Their sum must be the full image up to float rounding, and the full
  // image must be bit for bit the one rendered without them (the same random numbers).
  auto scene = sceneFile("cornell-spheres");
  std::vector<NamedImage> extras;
  ImageRGB full = renderWith(*scene, "bdpt", 24, 24, 4, 3, {{"max_depth", 4}}, 0, false, &extras, {{"aov", "strategies"}});
  ImageRGB plain = renderWith(*scene, "bdpt", 24, 24, 4, 3, {{"max_depth", 4}});
  CHECK(full.data == plain.data);
  REQUIRE(extras.size() == size_t(VertexConnectionMerging::strategyCount(4)));  // 2 + 3 + 4 + 5 + 6
  CHECK(extras.front().name == "s0t2");
  CHECK(extras.back().name == "s5t1");
  std::vector<double> sum(full.data.size(), 0.0);
  for (const NamedImage& e : extras)
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += e.image.data[i];
  double worst = 0, total = 0;
  for (size_t i = 0; i < sum.size(); ++i) {
    worst = std::max(worst, std::abs(sum[i] - full.data[i]) / std::max(1e-3, double(full.data[i])));
    total += sum[i];
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-4);
  CHECK(total / full.data.size() == Approx(meanOf(full)).epsilon(1e-5));
  // Every technique that can carry light here does: s = 0 and t = 1 at depth 1 included.
  for (const NamedImage& e : extras)
    if (e.name == "s0t3" || e.name == "s1t2" || e.name == "s2t2" || e.name == "s3t1") CHECK(meanOf(e.image) > 0);
}

TEST_CASE("bdpt: each technique alone, unweighted, converges to the path tracer's paths of its length - region by region") {
  // On the Cornell box every technique (s, t) of depth k = s + t − 2 is an unbiased estimator of
  // the light carried by paths of exactly k bounces: the path tracer's image at max_depth k
  // minus its image at k − 1. For k = 0, 1, 2 (the area light seen directly, direct lighting,
  // one indirect bounce) each of the k + 2 techniques at 24×24 pixels, against the path
  // tracer's difference image, over 4×4 regions of 6×6 pixels: z from both estimators' seed
  // noise; every |z| < 4.5 (a false alarm ~10⁻⁴ over the 48 values of a technique) and mean z²
  // below 3. A technique that counted its paths twice or missed a density would be off by far
  // more: the direct light alone differs between techniques by factors of 10² in noise but not
  // in level.
  auto scene = sceneFile("cornell-box");
  const int W = 24;
  auto path = [&](int depth, uint64_t seed) { return renderWith(*scene, "path", W, W, 256, seed, {{"max_depth", depth}}); };
  auto minus = [](ImageRGB a, const ImageRGB& b) {
    for (size_t i = 0; i < a.data.size(); ++i) a.data[i] -= b.data[i];
    return a;
  };
  ImageRGB previous1, previous2;
  for (int k = 0; k <= 2; ++k) {
    ImageRGB p1 = path(k, 1), p2 = path(k, 2);
    ImageRGB e1 = k == 0 ? p1 : minus(p1, previous1), e2 = k == 0 ? p2 : minus(p2, previous2);
    previous1 = p1, previous2 = p2;
    for (int s = 0; s <= k + 1; ++s) {
      const int t = k + 2 - s;
      INFO("technique s = " << s << ", t = " << t);
      auto technique = [&](uint64_t seed) {
        return renderWith(*scene, "bdpt", W, W, 256, seed + 10, {{"max_depth", k}, {"only_s", s}, {"only_t", t}});
      };
      ImageRGB b1 = technique(1), b2 = technique(2);
      RegionAgreement r = regions(b1, b2, e1, e2, 6, 1e-9);
      INFO("worst |z| " << r.worst << ", mean z² " << r.meanZ2 << "; means " << meanOf(b1) << " vs " << meanOf(e1));
      CHECK(r.worst < 4.5);
      CHECK(r.meanZ2 < 3.0);
      CHECK((meanOf(b1) + meanOf(b2)) / (meanOf(e1) + meanOf(e2)) == Approx(1.0).epsilon(0.05));
    }
  }
}

TEST_CASE("bdpt, vcm and bpm agree with the path tracer region by region on the Cornell box", "[long]") {
  // 32×32 pixels cut into 4×4 regions of 8×8, seeds 1 and 2, z as the light tracer's test: every
  // |z| < 4, mean z² < 3, image means within 1.5%. The merge radius (2 mm, a fifth of a pixel's
  // footprint) keeps vcm's and bpm's bias below their noise at 256 iterations. vcm twice: without
  // direct merges (its default) and with them (Georgiev et al.'s full set of techniques): each
  // set's weights must be a partition of unity on its own.
  auto scene = sceneFile("cornell-box");
  const int W = 32;
  ImageRGB p1 = renderWith(*scene, "path", W, W, 256, 1), p2 = renderWith(*scene, "path", W, W, 256, 2);
  for (const std::string variant : {"bdpt", "vcm", "vcm direct merges", "bpm"}) {
    INFO(variant);
    const std::string name = variant.substr(0, variant.find(' '));
    const std::map<std::string, std::string> choices = {{"direct_merges", variant == "vcm direct merges" ? "on" : "off"}};
    ImageRGB a1 = renderWith(*scene, name, W, W, 256, 1, {{"radius", 0.002}}, 0, false, nullptr, choices);
    ImageRGB a2 = renderWith(*scene, name, W, W, 256, 2, {{"radius", 0.002}}, 0, false, nullptr, choices);
    RegionAgreement r = regions(a1, a2, p1, p2, 8);
    INFO("worst |z| " << r.worst << ", mean z² " << r.meanZ2);
    CHECK(r.worst < 4.0);
    CHECK(r.meanZ2 < 3.0);
    CHECK((meanOf(a1) + meanOf(a2)) / (meanOf(p1) + meanOf(p2)) == Approx(1.0).epsilon(0.015));
  }
}

TEST_CASE("bidirectional methods are deterministic: the same image bit for bit with 1 or 2 threads - and spectral") {
  auto scene = sceneFile("cornell-spheres");
  for (const char* name : kBidirectional)
    for (bool spectral : {false, true})
      for (const char* sampler : {"independent", "sobol"}) {
        INFO(name << (spectral ? " spectral" : "") << ", " << sampler << " sampler");
        const std::map<std::string, std::string> choices{{"sampler", sampler}};
        ImageRGB one = renderWith(*scene, name, 40, 40, 2, 9, {}, 1, spectral, nullptr, choices);
        ImageRGB two = renderWith(*scene, name, 40, 40, 2, 9, {}, 2, spectral, nullptr, choices);
        CHECK(one.data == two.data);
        CHECK(renderWith(*scene, name, 40, 40, 2, 10, {}, 2, spectral, nullptr, choices).data != two.data);
      }
}

TEST_CASE("vcm and sppm agree region by region on the caustic scenes", "[long]") {
  // Both are consistent estimators with the same bias structure (a disc of initial radius r
  // around each camera vertex, shrinking with the iterations); with r a fifth of a pixel's
  // footprint (cornell-spheres) or about one (glass-caustic), the blur moves little light
  // across 8×8-pixel regions, and the regions must agree within their noise: every |z| < 4,
  // mean z² < 3, image means within 1.5%. glass-caustic's caustic is focused by a glass sphere
  // from a spot light: no path tracer finds it.
  struct Case {
    const char* scene;
    int width, height;
    double radius;
  };
  for (const Case& c : {Case{"glass-caustic", 32, 24, 0.02}, Case{"cornell-spheres", 32, 32, 0.004}}) {
    INFO(c.scene);
    auto scene = sceneFile(c.scene);
    auto sppm = [&](uint64_t seed) {
      RenderOptions ro;
      ro.width = c.width, ro.height = c.height, ro.seed = seed;
      return makeWith("sppm", {{"passes", 64}, {"photons_per_pass", 100000}, {"radius", c.radius}})->render(*scene, ro, nullptr);
    };
    ImageRGB s1 = sppm(1), s2 = sppm(2);
    ImageRGB v1 = renderWith(*scene, "vcm", c.width, c.height, 256, 1, {{"radius", c.radius}});
    ImageRGB v2 = renderWith(*scene, "vcm", c.width, c.height, 256, 2, {{"radius", c.radius}});
    RegionAgreement r = regions(v1, v2, s1, s2, 8);
    INFO("worst |z| " << r.worst << ", mean z² " << r.meanZ2);
    CHECK(r.worst < 4.0);
    CHECK(r.meanZ2 < 3.0);
    CHECK((meanOf(v1) + meanOf(v2)) / (meanOf(s1) + meanOf(s2)) == Approx(1.0).epsilon(0.015));
  }
}

TEST_CASE("vcm's bias vanishes: its squared bias against the mirror caustic's closed form falls as the radius shrinks", "[heavy]") {
  // Independent runs' errors against the exact image e are independent, so mean((a − e)(b − e))
  // over the pixels estimates the squared bias alone, without the noise; averaged over the 15
  // pairs of 6 runs (a U-statistic), its standard error from leaving out one run at a time (the
  // jackknife). With direct merges (most of vcm's bias is theirs, the blurred direct light) and
  // a large initial radius, 40 cm, so that the bias stands well above that error at the first
  // checkpoint: at r₁ = 8 cm it was below it (measured ±0.003–0.005 at 8 iterations, where the
  // squared bias is ~0.001), and a test of its sign there passed or failed by the seeds.
  // r_i = r₁ i^(−1/8) (α = 3/4); the bias of a disc average goes as r (the blur of a gradient's
  // edge) to r² (smooth parts), and merging's MIS weight shrinks with r² once it is small, so
  // the squared bias falls at least as r², by i^(−1/4): 64^(1/4) = 2.83× from iteration 8 to
  // 512. Checked: seen at 8 iterations (above 4 standard errors), falling at each step of ×8
  // by more than 3 standard errors of the difference, and by at least 2.83× overall (less 3
  // standard errors of b₈). Measured: 0.049, 0.021, 0.0089 (± 0.004, 0.0006–0.0012, 0.0001).
  MirrorCaustic mc;
  auto scene = mc.build();
  const int W = 24, K = 6;
  ImageRGB exact = expectedFloorImage(*scene, W, W, [&](const Vec3& x) { return mc.radiance(x); });
  std::vector<std::map<int, ImageRGB>> at(K);
  for (int k = 0; k < K; ++k) {
    RenderOptions ro;
    ro.width = ro.height = W;
    ro.spp = 512;
    ro.seed = uint64_t(k + 1);
    ro.checkpoint = [&, k](const ImageRGB& image, const RenderInfo& info) { at[size_t(k)][info.spp] = image; };
    makeWith("vcm", {{"spp", 512}, {"radius", 0.4}}, ro, {{"direct_merges", "on"}})->render(*scene, ro, nullptr);
  }
  auto cross = [&](int n, int j, int k) {  // runs j and k at iteration n, relative to the mean level²
    double s = 0;
    for (size_t i = 1; i < exact.data.size(); i += 3)
      s += (double(at[size_t(j)][n].data[i]) - exact.data[i]) * (double(at[size_t(k)][n].data[i]) - exact.data[i]);
    return s / double(exact.data.size() / 3) / (meanOf(exact) * meanOf(exact));
  };
  auto pairsWithout = [&](int n, int left) {  // the mean over the pairs that leave out run `left` (−1: none)
    double s = 0;
    int count = 0;
    for (int j = 0; j < K; ++j)
      for (int k = j + 1; k < K; ++k)
        if (j != left && k != left) s += cross(n, j, k), ++count;
    return s / count;
  };
  struct Estimate {
    double bias2, se;
  };
  auto estimate = [&](int n) {
    std::vector<double> leaveOut;
    double mean = 0, var = 0;
    for (int k = 0; k < K; ++k) leaveOut.push_back(pairsWithout(n, k)), mean += leaveOut.back() / K;
    for (double x : leaveOut) var += (x - mean) * (x - mean);
    return Estimate{pairsWithout(n, -1), std::sqrt(var * (K - 1) / K)};
  };
  const Estimate b8 = estimate(8), b64 = estimate(64), b512 = estimate(512);
  INFO("relative squared bias at 8, 64, 512 iterations: " << b8.bias2 << " ± " << b8.se << ", " << b64.bias2 << " ± "
                                                          << b64.se << ", " << b512.bias2 << " ± " << b512.se);
  CHECK(b8.bias2 > 4 * b8.se);
  CHECK(b64.bias2 < b8.bias2 - 3 * std::hypot(b8.se, b64.se));
  CHECK(b512.bias2 < b64.bias2 - 3 * std::hypot(b64.se, b512.se));
  CHECK(b512.bias2 < (b8.bias2 - 3 * b8.se) / 2.83);
}

TEST_CASE("bdpt and vcm agree with the path tracer on glossy surfaces - the glossy lobes' densities in the weights", "[heavy]") {
  // MIS weights sum to 1 over the techniques only if every technique computes the same pdf
  // ratios, forward and reverse; a wrong reverse density of a glossy lobe biases the sum. A
  // small room: a modified-Phong floor (SmallVCM's: kd 0.1, ks 0.7, n = 90), a rough GGX metal
  // back wall (α = 0.3), a metallic-roughness left wall, lit by an area light under the ceiling, which
  // every technique can reach. 32×32 pixels, regions of 8×8, seeds 1 and 2, 256 samples or
  // iterations: every |z| < 4, mean z² < 3, means within 1.5%. Both heuristics: the balance
  // heuristic weighs the same ratios to the first power, so a wrong density shows there too.
  Scene scene;
  uint32_t floor = scene.addMaterial({"phong", std::make_unique<Phong>(Spectrum(0.1f), Spectrum(0.7f), 90.0f), Spectrum(0), false});
  uint32_t metal = scene.addMaterial({"ggx", std::make_unique<GGXConductor>(ColorTexture(Spectrum(0.9f, 0.6f, 0.3f)), 0.3f),
                                      Spectrum(0), false});
  // The left wall: glTF's metallic-roughness mix (metallic 0.3, roughness 0.5), both lobes at once.
  uint32_t wall = scene.addMaterial({"metallic-roughness", std::make_unique<MetallicRoughness>(ColorTexture(Spectrum(0.6f, 0.5f, 0.4f)),
                                                                                            ColorTexture(Spectrum(1, 0.5f, 0.3f))),
                                     Spectrum(0), false});
  uint32_t light = scene.addMaterial({"light", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.0f))), Spectrum(8.0f), false});
  addQuad(scene, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, floor);
  addQuad(scene, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, metal);
  addQuad(scene, {-1, 0, 1}, {-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, wall);
  addRoomLight(scene, light);
  scene.setCamera(roomCamera());
  scene.commit();
  const int W = 32;
  ImageRGB p1 = renderWith(scene, "path", W, W, 256, 1), p2 = renderWith(scene, "path", W, W, 256, 2);
  REQUIRE(meanOf(p1) > 0.01);
  for (const char* heuristic : {"power", "balance"})
  for (const char* name : {"bdpt", "vcm"}) {
    INFO(name << ", " << heuristic << " heuristic");
    ImageRGB a1 = renderWith(scene, name, W, W, 256, 1, {{"radius", 0.005}}, 0, false, nullptr, {{"heuristic", heuristic}});
    ImageRGB a2 = renderWith(scene, name, W, W, 256, 2, {{"radius", 0.005}}, 0, false, nullptr, {{"heuristic", heuristic}});
    RegionAgreement r = regions(a1, a2, p1, p2, 8);
    INFO("worst |z| " << r.worst << ", mean z² " << r.meanZ2 << "; means " << meanOf(a1) << " vs " << meanOf(p1));
    CHECK(r.worst < 4.0);
    CHECK(r.meanZ2 < 3.0);
    CHECK((meanOf(a1) + meanOf(a2)) / (meanOf(p1) + meanOf(p2)) == Approx(1.0).epsilon(0.015));
  }
}
