#include "radiosity/patch_mesh.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "radiosity/form_factor.h"

namespace pl {

namespace {

// Faces of a scene triangle that get patches: both for a doubleSided material, else one.
int faceCount(const Material& m) { return m.twoSided ? 2 : 1; }

// A triangle without area (a UV sphere's poles) gets no patches: no ray hits it, nothing leaves it.
bool degenerate(const std::array<Vec3, 3>& v) { return !(glm::length(glm::cross(v[1] - v[0], v[2] - v[0])) > 0); }

float longestEdge(const std::array<Vec3, 3>& v) {
  return std::max({glm::length(v[1] - v[0]), glm::length(v[2] - v[1]), glm::length(v[0] - v[2])});
}

int subdivisions(float edge, float patchSize) {
  double n = std::ceil(double(edge) / patchSize);
  return int(std::clamp(n, 1.0, 65535.0));
}

// Sub-triangle indices on the n×n barycentric grid (grid point (a, b) is b1 = a/n, b2 = b/n):
// "up" triangles U(a, b) = {(a,b), (a+1,b), (a,b+1)} for a+b ≤ n−1 come first, row by row, then
// "down" triangles D(a, b) = {(a+1,b), (a+1,b+1), (a,b+1)} for a+b ≤ n−2.
size_t upIndex(int n, int a, int b) { return size_t(a) * n - size_t(a) * (a - 1) / 2 + b; }
size_t downIndex(int n, int a, int b) {
  return size_t(n) * (n + 1) / 2 + size_t(a) * (n - 1) - size_t(a) * (a - 1) / 2 + b;
}

// A shared vertex's identity: its position on a grid far finer than any patch, its normal's
// direction to 1e-3 and its material and face. Grid points are computed in double from the
// triangle's corners with exact barycentric weights, so a point on an edge comes out the same
// (to ~1e-16) from both triangles that share the edge and never straddles a rounding boundary
// in practice.
struct VertexKey {
  int64_t p[3];
  int32_t n[3];
  uint32_t material;
  bool operator==(const VertexKey& o) const {
    return p[0] == o.p[0] && p[1] == o.p[1] && p[2] == o.p[2] && n[0] == o.n[0] && n[1] == o.n[1] && n[2] == o.n[2] &&
           material == o.material;
  }
};
struct VertexKeyHash {
  size_t operator()(const VertexKey& k) const {
    uint64_t h = 0xcbf29ce484222325ULL;
    auto mix = [&](uint64_t v) { h = (h ^ v) * 0x100000001b3ULL; };
    for (int i = 0; i < 3; ++i) mix(uint64_t(k.p[i])), mix(uint64_t(uint32_t(k.n[i])));
    mix(k.material);
    return size_t(h);
  }
};

}  // namespace

size_t PatchMesh::count(const Scene& scene, float patchSize) {
  size_t total = 0;
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
    if (degenerate(scene.trianglePositions(t))) continue;
    int n = subdivisions(longestEdge(scene.trianglePositions(t)), patchSize);
    total += size_t(n) * n * faceCount(scene.materials()[scene.triangleMaterial(t)]);
  }
  return total;
}

float PatchMesh::patchSizeFor(const Scene& scene, size_t budget) {
  float longest = 0.0f;
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) longest = std::max(longest, longestEdge(scene.trianglePositions(t)));
  if (!(longest > 0)) return 1.0f;
  // The smallest size whose count fits the budget: count(h) does not grow with h.
  double hi = longest, lo = longest * 1e-6;
  if (count(scene, float(hi)) > budget) return float(hi);  // one patch per face is the least there is
  for (int i = 0; i < 40; ++i) {
    double mid = std::sqrt(lo * hi);
    (count(scene, float(mid)) <= budget ? hi : lo) = mid;
  }
  return float(hi);
}

PatchMesh::PatchMesh(const Scene& scene, float patchSize) : patchSize_(patchSize) {
  if (!(patchSize > 0)) throw Error("radiosity: the patch size must be positive");
  const double quantum = std::max(1e-9, 1e-7 * 2.0 * scene.bounds().radius());
  std::unordered_map<VertexKey, uint32_t, VertexKeyHash> vertices;
  std::vector<bool> namedNonDiffuse(scene.materials().size(), false);
  faces_.resize(scene.triangleCount());
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
    const std::array<Vec3, 3> v = scene.trianglePositions(t);
    if (degenerate(v)) continue;
    const uint32_t materialIndex = scene.triangleMaterial(t);
    const Material& material = scene.materials()[materialIndex];
    const int n = subdivisions(longestEdge(v), patchSize);
    Faces& faces = faces_[t];
    faces.n = n;
    const SurfaceHit centre = scene.surfaceAt(t, 1.0f / 3, 1.0f / 3);
    const bool emitter = !isBlack(material.emission);
    // Which face is the front: the emitting one, or the one the shading normal points to.
    float side = 1.0f;
    if (!emitter && !material.twoSided && glm::dot(centre.shading.n, centre.ng) < 0) side = -1.0f;
    faces.normal = side * centre.ng;

    Spectrum reflectance(0.0f);
    if (material.bsdf && material.bsdf->bsdfClass() == BSDFClass::kLambertian) {
      // f = ρ/π for a Lambertian BSDF, whatever the directions.
      reflectance = kPi * material.bsdf->eval(Vec3(0, 0, 1), Vec3(0, 0, 1), bsdfContext(centre));
    } else if (material.bsdf && !namedNonDiffuse[materialIndex]) {
      namedNonDiffuse[materialIndex] = true;
      nonDiffuse_.push_back(material.name.empty() ? "#" + std::to_string(materialIndex) : material.name);
    }
    const AreaLight* light = scene.triangleLight(t);
    const Spectrum exitance = light ? kPi * light->meanRadiance() : Spectrum(0.0f);

    for (int face = 0; face < faceCount(material); ++face) {
      const Vec3 normal = face == 0 ? faces.normal : -faces.normal;
      faces.first[face] = int(patches_.size());
      // Grid points in double, with exact weights (n − a − b, a, b)/n.
      auto gridPoint = [&](int a, int b) {
        double w0 = double(n - a - b) / n, w1 = double(a) / n, w2 = double(b) / n;
        glm::dvec3 p = w0 * glm::dvec3(v[0]) + w1 * glm::dvec3(v[1]) + w2 * glm::dvec3(v[2]);
        return p;
      };
      auto vertex = [&](int a, int b) -> uint32_t {
        glm::dvec3 p = gridPoint(a, b);
        Vec3 shadingNormal = normal;
        SurfaceHit s = scene.surfaceAt(t, float(a) / n, float(b) / n);
        if (glm::dot(s.shading.n, normal) > 0) shadingNormal = s.shading.n;
        else if (glm::dot(s.shading.n, normal) < 0) shadingNormal = -s.shading.n;
        VertexKey key;
        for (int k = 0; k < 3; ++k) {
          key.p[k] = std::llround(p[k] / quantum);
          key.n[k] = int32_t(std::lround(shadingNormal[k] * 1000.0f));
        }
        key.material = materialIndex * 2 + uint32_t(face);
        auto it = vertices.emplace(key, uint32_t(vertices.size())).first;
        return it->second;
      };
      auto addPatch = [&](int a0, int b0, int a1, int b1, int a2, int b2) {
        Patch p;
        const int grid[3][2] = {{a0, b0}, {a1, b1}, {a2, b2}};
        for (int k = 0; k < 3; ++k) {
          p.v[k] = Vec3(gridPoint(grid[k][0], grid[k][1]));
          p.corner[k] = vertex(grid[k][0], grid[k][1]);
        }
        p.normal = normal;
        p.centroid = (p.v[0] + p.v[1] + p.v[2]) / 3.0f;
        p.area = 0.5f * glm::length(glm::cross(p.v[1] - p.v[0], p.v[2] - p.v[0]));
        p.size = longestEdge({p.v[0], p.v[1], p.v[2]});
        p.reflectance = reflectance;
        // One-sided emitters emit from their counter-clockwise face, which is face 0. An
        // emissive texture's patch takes M = π·Le at its centroid (the midpoint rule).
        Spectrum M = exitance;
        if (light && light->textured()) {
          const float ca = float(a0 + a1 + a2) / (3.0f * n), cb = float(b0 + b1 + b2) / (3.0f * n);
          M = kPi * light->radiance(scene.surfaceAt(t, ca, cb).uv, SampledWavelengths::rgb());
        }
        p.exitance = (face == 0 || material.twoSided) ? M : Spectrum(0.0f);
        p.primitive = t;
        patches_.push_back(p);
      };
      for (int a = 0; a < n; ++a)
        for (int b = 0; a + b <= n - 1; ++b) addPatch(a, b, a + 1, b, a, b + 1);
      for (int a = 0; a + 1 < n; ++a)
        for (int b = 0; a + b <= n - 2; ++b) addPatch(a + 1, b, a + 1, b + 1, a, b + 1);
    }
  }
  vertexCount_ = vertices.size();
  findBuriedPoints(scene);
}

void PatchMesh::findBuriedPoints(const Scene& scene) {
  // Buried: the ray along the normal reaches the back of a one-sided surface within one patch
  // size (a thin cover: the ceiling just above a light panel), or five rays (the normal and
  // four at 60° from it) all reach backs, the inside of a closed object (the floor under a
  // box). The normal ray alone would also call buried a point under a ceiling whose patches
  // face away from the room.
  const float eps = scene.epsilon();
  for (Patch& p : patches_) {
    Vec3 points[16];
    subCentroids(p.v, 4, points);
    const Frame frame(p.normal);
    for (int k = 0; k < 16; ++k) {
      bool buried = true;
      for (int d = 0; d < 5 && buried; ++d) {
        Vec3 w = d == 0 ? p.normal : frame.toWorld(Vec3(0.8660254f * std::cos(kPi / 2 * d), 0.8660254f * std::sin(kPi / 2 * d), 0.5f));
        SurfaceHit hit;
        if (!scene.intersect(Ray{points[k] + eps * p.normal, w, 0.0f, INFINITY}, &hit)) buried = false;
        else buried = locate(hit.primitive, hit.barycentric, -w) < 0;
        if (buried && d == 0 && hit.t < p.size) break;  // a thin cover
      }
      if (buried) p.exposed &= uint16_t(~(1u << k));
    }
  }
}

int PatchMesh::locate(uint32_t primitive, const Vec2& bary, const Vec3& w, Vec3* weights) const {
  const Faces& faces = faces_[primitive];
  const int face = glm::dot(w, faces.normal) >= 0 ? 0 : 1;
  if (faces.first[face] < 0) return -1;
  const int n = faces.n;
  float x = bary.x * n, y = bary.y * n;
  int a = std::clamp(int(std::floor(x)), 0, n - 1);
  int b = std::clamp(int(std::floor(y)), 0, n - 1 - a);
  float fx = x - a, fy = y - b;
  size_t local;
  Vec3 wts;
  if (fx + fy <= 1.0f || a + b == n - 1) {
    local = upIndex(n, a, b);
    wts = Vec3(1.0f - fx - fy, fx, fy);
  } else {
    local = downIndex(n, a, b);
    wts = Vec3(1.0f - fy, fx + fy - 1.0f, 1.0f - fx);
  }
  if (weights) {
    wts = glm::clamp(wts, Vec3(0.0f), Vec3(1.0f));
    float sum = wts.x + wts.y + wts.z;
    *weights = sum > 0 ? wts / sum : Vec3(1.0f / 3);
  }
  return faces.first[face] + int(local);
}

std::vector<Spectrum> PatchMesh::vertexValues(const std::vector<Spectrum>& patchValues) const {
  std::vector<Spectrum> sum(vertexCount_, Spectrum(0.0f));
  std::vector<float> area(vertexCount_, 0.0f);
  for (size_t i = 0; i < patches_.size(); ++i) {
    // Weighted by the exposed area: a buried corner takes its value from the visible part.
    const float a = patches_[i].area * patches_[i].exposure();
    for (uint32_t c : patches_[i].corner) {
      sum[c] += a * patchValues[i];
      area[c] += a;
    }
  }
  for (size_t c = 0; c < vertexCount_; ++c)
    if (area[c] > 0) sum[c] /= area[c];
  return sum;
}

}  // namespace pl
