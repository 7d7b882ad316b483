// Classic radiosity (integrators/radiosity.cpp, radiosity/): form factors against view-factor
// tables' closed forms and against the definition integrated numerically, reciprocity, the
// closed furnace's B = E/(1 − ρ), every light over a floor against ρ/π·E, and the diffuse
// Cornell box against the path tracer, its error shrinking with the patches. The solution is
// deterministic: tolerances come from the discretisation (stated per test), not from noise.
#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>

#include "integrator_helpers.h"
#include "bsdfs/dielectric.h"
#include "integrators/radiosity.h"
#include "radiosity/form_factor.h"
#include "scene/gltf_loader.h"
#include "scene_helpers.h"

using namespace pl;
using namespace pl::test;

namespace {

std::unique_ptr<Scene> sceneFile(const char* name) {
  return loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/" + name + ".gltf");
}

// The definition, ∫ cosθx cosθy / (π r²) dA over the part of the triangle in front of x, by the
// midpoint rule on N² congruent sub-triangles. Independent of the closed form under test.
double formFactorByQuadrature(const Vec3& x, const Vec3& n, const Vec3 (&t)[3], int N) {
  glm::dvec3 a(t[0]), e1 = glm::dvec3(t[1]) - a, e2 = glm::dvec3(t[2]) - a;
  glm::dvec3 m = glm::cross(e1, e2);
  const double area = 0.5 * glm::length(m) / (double(N) * N);
  m = glm::normalize(m);
  double sum = 0;
  auto add = [&](double u, double v) {
    glm::dvec3 d = a + (u / N) * e1 + (v / N) * e2 - glm::dvec3(x);
    double r2 = glm::dot(d, d), r = std::sqrt(r2);
    double cx = glm::dot(glm::dvec3(n), d) / r, cy = std::abs(glm::dot(m, d)) / r;
    if (cx > 0) sum += cx * cy / (kPi * r2) * area;
  };
  for (int i = 0; i < N; ++i)
    for (int j = 0; i + j <= N - 1; ++j) add(i + 1.0 / 3, j + 1.0 / 3);
  for (int i = 0; i + 1 < N; ++i)
    for (int j = 0; i + j <= N - 2; ++j) add(i + 2.0 / 3, j + 2.0 / 3);
  return sum;
}

// View-factor catalogue (Howell, "A Catalog of Radiation Heat Transfer Configuration Factors"):
// B-3, a differential element to a parallel a×b rectangle whose corner is above it at height c.
double elementToParallelRectangle(double a, double b, double c) {
  double A = a / c, B = b / c;
  return (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
          B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B))) /
         (2 * kPi);
}

// C-11: two identical directly opposed parallel a×b rectangles at distance c.
double parallelRectangles(double a, double b, double c) {
  double X = a / c, Y = b / c;
  return 2 / (kPi * X * Y) *
         (std::log(std::sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) +
          X * std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y)) +
          Y * std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) - X * std::atan(X) - Y * std::atan(Y));
}

// C-14: from a w×l rectangle to an h×l rectangle at a right angle sharing the edge l.
double perpendicularRectangles(double w, double h, double l) {
  double W = w / l, H = h / l, s = W * W + H * H;
  double log = std::log((1 + W * W) * (1 + H * H) / (1 + s)) +
               W * W * std::log(W * W * (1 + s) / ((1 + W * W) * s)) +
               H * H * std::log(H * H * (1 + s) / ((1 + H * H) * s));
  return (W * std::atan(1 / W) + H * std::atan(1 / H) - std::sqrt(s) * std::atan(1 / std::sqrt(s)) + 0.25 * log) / (kPi * W);
}

// A quad facing `normal` (its front), centred at c, spanned by ±u, ±v.
void addFacing(Scene& s, Vec3 c, Vec3 u, Vec3 v, Vec3 normal, uint32_t material) {
  if (glm::dot(glm::cross(u, v), normal) < 0) std::swap(u, v);
  addQuad(s, c - u - v, c + u - v, c + u + v, c - u + v, material);
}

// The form factor from the surface made of primitives [a0, a1) to that of [b0, b1), from the
// patches' matrix: F_AB = Σ_{i∈A} A_i Σ_{j∈B} F_ij / A_A.
double surfaceFormFactor(const PatchMesh& mesh, const FormFactorMatrix& F, uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1) {
  double sum = 0, area = 0;
  const auto& p = mesh.patches();
  for (size_t i = 0; i < p.size(); ++i) {
    if (p[i].primitive < a0 || p[i].primitive >= a1) continue;
    area += p[i].area;
    for (size_t j = 0; j < p.size(); ++j)
      if (p[j].primitive >= b0 && p[j].primitive < b1) sum += p[i].area * F.row(i)[j];
  }
  return sum / area;
}

struct Exchange {
  double ab, ba;
};
Exchange meshedFormFactors(const Scene& scene, float patchSize) {
  PatchMesh mesh(scene, patchSize);
  FormFactorMatrix F(mesh.size());
  Budget budget;
  computeFormFactors(scene, mesh, 2, budget, &F);
  REQUIRE(F.complete);
  return {surfaceFormFactor(mesh, F, 0, 2, 2, 4), surfaceFormFactor(mesh, F, 2, 4, 0, 2)};
}

ImageRGB renderRadiosity(const Scene& scene, int W, int spp, std::map<std::string, double> values,
                         const std::string& display = "smooth", int threads = 0, RadiosityIntegrator** out = nullptr,
                         std::unique_ptr<Integrator>* keep = nullptr) {
  RenderOptions ro;
  ro.width = ro.height = W;
  ro.spp = spp;
  ro.threads = threads;
  values["spp"] = spp;
  auto integrator = makeWith("radiosity", values, ro, {{"display", display}});
  ImageRGB image = integrator->render(scene, ro, nullptr);
  if (out) *out = dynamic_cast<RadiosityIntegrator*>(integrator.get());
  if (keep) *keep = std::move(integrator);
  return image;
}

}  // namespace

TEST_CASE("radiosity: the point-to-triangle form factor matches the catalogue and the definition") {
  const Vec3 x(0, 0, 0), n(0, 0, 1);
  // B-3 at heights 1 and 0.01 (the closed form stays exact where a point estimate would diverge):
  // the rectangle [0, 0.7] × [0, 0.4] at height c, as two triangles.
  for (double c : {1.0, 0.01}) {
    INFO("height " << c);
    const Vec3 t1[3] = {{0, 0, float(c)}, {0.7f, 0, float(c)}, {0.7f, 0.4f, float(c)}};
    const Vec3 t2[3] = {{0, 0, float(c)}, {0.7f, 0.4f, float(c)}, {0, 0.4f, float(c)}};
    double f = double(pointToTriangle(x, n, t1)) + pointToTriangle(x, n, t2);
    CHECK(f == Approx(elementToParallelRectangle(0.7, 0.4, c)).epsilon(1e-5));
  }
  // Tilted and cut by the tangent plane: only the part in front counts. Against the definition
  // on 400² sub-triangles (midpoint rule: error O(N⁻²) away from x, ~10⁻⁵ here).
  const Vec3 tilted[3] = {{-0.5f, 0.3f, -0.4f}, {0.6f, 0.5f, 0.7f}, {-0.2f, 1.1f, 0.5f}};
  CHECK(pointToTriangle(x, n, tilted) == Approx(formFactorByQuadrature(x, n, tilted, 400)).epsilon(1e-3));
  CHECK(pointToTriangle(x, n, tilted) > 0.01);
  // Wholly behind: nothing.
  const Vec3 below[3] = {{0, 0, -1}, {1, 0, -1}, {0, 1, -2}};
  CHECK(pointToTriangle(x, n, below) == 0.0f);
}

TEST_CASE("radiosity: meshed form factors match the catalogue's closed forms and obey reciprocity") {
  // Surfaces A (primitives 0, 1) and B (2, 3), meshed into patches of 10 cm (A = 1 m²: 200
  // patches) and 5 cm, F_AB from the patch matrix. Accepted: within 1% of the closed form;
  // the quadrature (16 points where patches are near, Wallace's disc estimate beyond 4 patch
  // sizes) errs by ~0.1–0.5% here, a missing cosine or a wrong clipping by far more.
  SECTION("parallel unit squares at distances 1 and 0.2 (C-11)") {
    for (float c : {1.0f, 0.2f}) {
      INFO("distance " << c);
      Scene s;
      uint32_t m = lambertian(s, 0.5f);
      addFacing(s, Vec3(0.5f, 0, 0.5f), Vec3(0.5f, 0, 0), Vec3(0, 0, 0.5f), Vec3(0, 1, 0), m);
      addFacing(s, Vec3(0.5f, c, 0.5f), Vec3(0.5f, 0, 0), Vec3(0, 0, 0.5f), Vec3(0, -1, 0), m);
      s.commit();
      const double expected = parallelRectangles(1, 1, c);
      for (float h : {0.1f, 0.05f}) {
        Exchange f = meshedFormFactors(s, h);
        INFO("patch size " << h << ": F_AB " << f.ab << ", F_BA " << f.ba << ", closed form " << expected);
        CHECK(f.ab == Approx(expected).epsilon(0.01));
        CHECK(f.ba == Approx(expected).epsilon(0.01));
      }
    }
  }
  SECTION("perpendicular rectangles sharing an edge, unequal areas (C-14): A_A F_AB = A_B F_BA") {
    // A: 0.5 × 1 on the floor, B: 1.5 × 1 upright on A's edge x = 0.
    Scene s;
    uint32_t m = lambertian(s, 0.5f);
    addFacing(s, Vec3(0.25f, 0, 0.5f), Vec3(0.25f, 0, 0), Vec3(0, 0, 0.5f), Vec3(0, 1, 0), m);
    addFacing(s, Vec3(0, 0.75f, 0.5f), Vec3(0, 0.75f, 0), Vec3(0, 0, 0.5f), Vec3(1, 0, 0), m);
    s.commit();
    const double ab = perpendicularRectangles(0.5, 1.5, 1.0), ba = ab * 0.5 / 1.5;
    Exchange f = meshedFormFactors(s, 0.05f);
    INFO("F_AB " << f.ab << " (closed form " << ab << "), F_BA " << f.ba << " (" << ba << ")");
    CHECK(f.ab == Approx(ab).epsilon(0.01));
    CHECK(f.ba == Approx(ba).epsilon(0.01));
    // Reciprocity between the two computed values: F_AB and F_BA come from different
    // quadrature points (A's and B's), so this is not true by construction.
    CHECK(0.5 * f.ab == Approx(1.5 * f.ba).epsilon(0.01));
  }
  SECTION("an opaque plate between the squares: visibility makes it zero") {
    Scene s;
    uint32_t m = lambertian(s, 0.5f);
    addFacing(s, Vec3(0.5f, 0, 0.5f), Vec3(0.5f, 0, 0), Vec3(0, 0, 0.5f), Vec3(0, 1, 0), m);
    addFacing(s, Vec3(0.5f, 1, 0.5f), Vec3(0.5f, 0, 0), Vec3(0, 0, 0.5f), Vec3(0, -1, 0), m);
    addFacing(s, Vec3(0.5f, 0.5f, 0.5f), Vec3(0.6f, 0, 0), Vec3(0, 0, 0.6f), Vec3(0, 1, 0), m);
    s.commit();
    Exchange f = meshedFormFactors(s, 0.1f);
    CHECK(f.ab == 0.0);
    CHECK(f.ba == 0.0);
  }
}

TEST_CASE("radiosity: the closed furnace has B = M/(1 − ρ) on every patch and L = 2 in every pixel", "[heavy]") {
  // scenes/furnace.gltf: every wall emits Le = 1 and reflects ρ = 0.5, so B = πLe/(1 − ρ) = 2π
  // and L = B/π = 2. Each patch's row of form factors sums to 1 in a closed scene; the
  // quadrature's error in those sums (≤ 0.5% measured) moves B by at most
  // ρ/(1 − ρ) × that = 0.5%; the solver's tolerance 1e-6 adds nothing visible. Accepted: every
  // patch's B and every pixel within 1%.
  auto scene = sceneFile("furnace");
  RadiosityIntegrator* radiosity = nullptr;
  std::unique_ptr<Integrator> keep;
  for (const char* display : {"smooth", "flat"}) {
    INFO(display);
    ImageRGB image = renderRadiosity(*scene, 16, 1, {{"patches", 1500}, {"tolerance", 1e-6}}, display, 0, &radiosity, &keep);
    REQUIRE(radiosity->solution().converged);
    double worstPatch = 0, worstPixel = 0;
    for (size_t i = 0; i < radiosity->mesh().size(); ++i) {
      const Spectrum& B = radiosity->solution().radiosity[i];
      worstPatch = std::max(worstPatch, std::abs(double(B.g) / (2 * kPi) - 1));
    }
    for (float v : image.data) worstPixel = std::max(worstPixel, std::abs(v / 2.0 - 1));
    INFO(radiosity->mesh().size() << " patches; worst patch " << worstPatch << ", worst pixel " << worstPixel);
    CHECK(radiosity->mesh().size() > 1000);
    CHECK(worstPatch < 0.01);
    CHECK(worstPixel < 0.01);
  }
  // The final gather: Le + a shadow ray to one of the emitting walls + the reflected radiosity
  // one bounce away, an unbiased estimate of the same 2. 16×16 pixels, 64 samples: the mean's
  // noise is ~0.2%; within 1%.
  ImageRGB gathered = renderRadiosity(*scene, 16, 64, {{"patches", 1500}, {"tolerance", 1e-6}}, "gather");
  CHECK(meanOf(gathered) == Approx(2.0).epsilon(0.01));
}

TEST_CASE("radiosity: a hit's patch is the one that contains it, on the face it is seen from") {
  // Every patch of a two-faced (doubleSided) and a one-sided triangle: points drawn in each
  // patch (barycentric on the scene triangle) must locate to that patch from its front and to
  // the other face's patch, or none, from behind.
  Scene s;
  uint32_t one = lambertian(s, 0.5f);
  uint32_t two = s.addMaterial({"two", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.5f))), Spectrum(0), true});
  s.addMesh({{0, 0, 0}, {1, 0, 0}, {0.3f, 0.8f, 0}}, {}, {}, {0, 1, 2}, one);
  s.addMesh({{0, 0, 1}, {0.7f, 0.1f, 1}, {0.2f, 0.9f, 1}}, {}, {}, {0, 1, 2}, two);
  s.commit();
  PatchMesh mesh(s, 0.13f);
  // Longest edges 1.063 and 0.943 m: 9 and 8 subdivisions; the second triangle has two faces.
  REQUIRE(mesh.size() == 9 * 9 + 2 * 8 * 8);
  Rng rng(7);
  for (size_t i = 0; i < mesh.size(); ++i) {
    const Patch& p = mesh.patches()[i];
    auto positions = s.trianglePositions(p.primitive);
    for (int k = 0; k < 20; ++k) {
      // A point inside the patch, then its barycentric coordinates on the scene triangle.
      Vec2 u = sampleUniformTriangle(Vec2(rng.uniform(), rng.uniform()));
      Vec3 x = (1 - u.x - u.y) * p.v[0] + u.x * p.v[1] + u.y * p.v[2];
      Vec3 e1 = positions[1] - positions[0], e2 = positions[2] - positions[0], d = x - positions[0];
      float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
      float det = d11 * d22 - d12 * d12;
      Vec2 b((d22 * glm::dot(d, e1) - d12 * glm::dot(d, e2)) / det, (d11 * glm::dot(d, e2) - d12 * glm::dot(d, e1)) / det);
      Vec3 w;
      INFO("patch " << i << ", barycentric " << b.x << ", " << b.y);
      REQUIRE(mesh.locate(p.primitive, b, p.normal, &w) == int(i));
      CHECK(glm::length((w.x * p.v[0] + w.y * p.v[1] + w.z * p.v[2]) - x) < 1e-5f);
      int behind = mesh.locate(p.primitive, b, -p.normal);
      if (p.primitive == 0) CHECK(behind == -1);
      else CHECK((behind >= 0 && behind != int(i) && mesh.patches()[behind].primitive == 1));
    }
  }
}

TEST_CASE("radiosity: the diffuse Cornell box agrees with the path tracer region by region, better with smaller patches", "[long]") {
  // scenes/cornell-box.gltf is diffuse (two white blocks, no spheres). The path tracer at
  // 32×32 pixels, 1024 samples, seeds 1 and 2, is the converged answer: over 4×4 regions of 8×8
  // pixels its noise is ~0.3% (from the seeds' difference). Radiosity with the final gather
  // (direct light by shadow rays, indirect from the solution one bounce away; 256 samples:
  // ~0.3% per region) at ~500 and ~8000 patches. Accepted: every region within 3% of the path
  // tracer at 8000 patches (measured 1.8% at 128², scripts/radiosity_convergence.py), and the
  // worst and mean region errors both smaller at 8000 than at 500: the discretisation error
  // shrinks with the patches (~2× per 4× patches, first order in the patch size; at 500 the
  // floor's shadow in front of the short block is two patches wide and the block's face, lit
  // only by that floor, comes out 17% too bright). Smooth display (the solution alone, no
  // shadow rays) shrinks its error too and stays within 4% at 8000 (measured 2.0% at 128²);
  // 256 samples there too, or the light's anti-aliased outline would be what is measured.
  auto scene = sceneFile("cornell-box");
  const int W = 32, B = 8;
  auto path = [&](uint64_t seed) {
    RenderOptions ro;
    ro.width = ro.height = W;
    ro.spp = 1024;
    ro.seed = seed;
    return makeWith("path", {{"spp", 1024}}, ro)->render(*scene, ro, nullptr);
  };
  ImageRGB p1 = path(1), p2 = path(2);
  // Relative to the region's level, or to a tenth of the mean region's when darker: a region
  // at 1% of the image's level (the short block's shadowed front face) would otherwise turn
  // an error invisible in the image into the largest number.
  auto regionErrors = [&](const ImageRGB& image) {
    std::vector<double> a, p;
    for (int by = 0; by < W / B; ++by)
      for (int bx = 0; bx < W / B; ++bx) {
        a.push_back(0), p.push_back(0);
        for (int y = by * B; y < (by + 1) * B; ++y)
          for (int x = bx * B; x < (bx + 1) * B; ++x) {
            Spectrum s = image.at(x, y), s1 = p1.at(x, y), s2 = p2.at(x, y);
            a.back() += s.r + s.g + s.b;
            p.back() += (s1.r + s2.r + s1.g + s2.g + s1.b + s2.b) / 2;
          }
      }
    const double floor = 0.1 * std::accumulate(p.begin(), p.end(), 0.0) / p.size();
    std::vector<double> errors;
    for (size_t i = 0; i < a.size(); ++i) errors.push_back(std::abs(a[i] - p[i]) / std::max(p[i], floor));
    return errors;
  };
  auto worst = [](const std::vector<double>& e) { return *std::max_element(e.begin(), e.end()); };
  auto mean = [](const std::vector<double>& e) { return std::accumulate(e.begin(), e.end(), 0.0) / e.size(); };
  std::vector<double> coarse = regionErrors(renderRadiosity(*scene, W, 256, {{"patches", 500}}, "gather"));
  std::vector<double> fine = regionErrors(renderRadiosity(*scene, W, 256, {{"patches", 8000}}, "gather"));
  std::vector<double> smoothCoarse = regionErrors(renderRadiosity(*scene, W, 256, {{"patches", 500}}, "smooth"));
  std::vector<double> smoothFine = regionErrors(renderRadiosity(*scene, W, 256, {{"patches", 8000}}, "smooth"));
  INFO("gather, 500 patches: worst " << worst(coarse) << ", mean " << mean(coarse) << "; 8000: worst " << worst(fine)
                                      << ", mean " << mean(fine) << "; smooth 500: worst " << worst(smoothCoarse) << ", mean "
                                      << mean(smoothCoarse) << "; 8000: worst " << worst(smoothFine) << ", mean " << mean(smoothFine));
  CHECK(worst(fine) < 0.03);
  CHECK(worst(fine) < worst(coarse));
  CHECK(mean(fine) < mean(coarse));
  CHECK(worst(smoothFine) < 0.04);
  CHECK(worst(smoothFine) < worst(smoothCoarse));
  CHECK(mean(smoothFine) < mean(smoothCoarse));
}

TEST_CASE("radiosity: the same image whatever the thread count") {
  auto scene = sceneFile("cornell-box");
  for (const char* display : {"smooth", "flat", "gather"}) {
    INFO(display);
    ImageRGB one = renderRadiosity(*scene, 24, 4, {{"patches", 800}}, display, 1);
    ImageRGB two = renderRadiosity(*scene, 24, 4, {{"patches", 800}}, display, 2);
    CHECK(one.data == two.data);
  }
}

TEST_CASE("radiosity: non-diffuse materials are black and named once - the patches view") {
  // A floor under a point light with a mirror and a glass pane standing on it.
  Scene s;
  addFacing(s, Vec3(0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), lambertian(s, 0.8f));
  uint32_t mirror = s.addMaterial({"mirror", std::make_unique<Mirror>(ColorTexture(Spectrum(0.9f))), Spectrum(0), false});
  uint32_t glass = s.addMaterial({"glass", std::make_unique<Dielectric>(1.5f), Spectrum(0), false});
  addFacing(s, Vec3(0.5f, 0.3f, 0), Vec3(0, 0.3f, 0), Vec3(0, 0, 0.3f), Vec3(-1, 0, 0), mirror);
  addFacing(s, Vec3(-0.5f, 0.3f, 0), Vec3(0, 0.3f, 0), Vec3(0, 0, 0.3f), Vec3(1, 0, 0), glass);
  addFacing(s, Vec3(-0.6f, 0.3f, 0.2f), Vec3(0, 0.3f, 0), Vec3(0, 0, 0.3f), Vec3(1, 0, 0), glass);
  s.addLight(std::make_unique<PointLight>(Vec3(0, 1.5f, 0), Spectrum(5.0f)));
  s.setCamera(lookingDown(2.5f, 1.0f));
  s.commit();
  RenderOptions ro;
  ro.width = ro.height = 24;
  ro.spp = 1;
  auto integrator = makeWith("radiosity", {{"patch_size", 0.1}, {"spp", 1}}, ro, {{"aov", "patches"}});
  ImageRGB image = integrator->render(s, ro, nullptr);
  std::vector<std::string> warnings = integrator->warnings();
  REQUIRE(warnings.size() == 2);
  CHECK(warnings[0].find("'mirror'") != std::string::npos);
  CHECK(warnings[1].find("'glass'") != std::string::npos);
  auto* radiosity = dynamic_cast<RadiosityIntegrator*>(integrator.get());
  float brightest = 0;
  for (size_t i = 0; i < radiosity->mesh().size(); ++i) {
    const Patch& p = radiosity->mesh().patches()[i];
    if (s.triangleMaterial(p.primitive) != 0) CHECK(isBlack(radiosity->solution().radiosity[i]));
    brightest = std::max(brightest, maxComponent(radiosity->solution().radiosity[i]) * kInvPi);
  }
  // The patches view: the image's size, each pixel a patch's flat B/π or darker on its edges.
  std::vector<NamedImage> extras = integrator->extraImages();
  REQUIRE(extras.size() == 1);
  CHECK(extras[0].name == "patches");
  CHECK(extras[0].image.width == 24);
  CHECK(*std::max_element(extras[0].image.data.begin(), extras[0].image.data.end()) <= brightest);
  CHECK(meanOf(extras[0].image) > 0.2 * meanOf(image));
}
