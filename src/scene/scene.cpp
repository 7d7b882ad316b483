#include "scene/scene.h"

#include <cstring>

#include <atomic>
#include <limits>

namespace pl {

namespace {
std::atomic<uint64_t> finishedThreadRays{0};
struct RayCounter {
  uint64_t count = 0;
  ~RayCounter() { finishedThreadRays += count; }
};
thread_local RayCounter rayCounter;
}  // namespace

uint64_t Scene::raysTraced() { return finishedThreadRays.load() + rayCounter.count; }

Scene::Scene() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
}

Scene::~Scene() {
  if (rtcScene_) rtcReleaseScene(rtcScene_);
  if (device_) rtcReleaseDevice(device_);
}

uint32_t Scene::addMaterial(Material material) {
  materials_.push_back(std::move(material));
  return uint32_t(materials_.size() - 1);
}

void Scene::addMesh(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                    const std::vector<Vec2>& uvs, const std::vector<uint32_t>& indices, uint32_t material,
                    const std::vector<glm::vec4>& tangents) {
  if (indices.size() % 3) throw Error("mesh index count is not a multiple of 3");
  if (material >= materials_.size()) throw Error("mesh refers to an unknown material");
  uint32_t base = uint32_t(positions_.size());
  bool smooth = !normals.empty();
  for (size_t i = 0; i < positions.size(); ++i) {
    // Coordinates within 1e-30 m of zero are zero. Differences of values near FLT_MIN underflow
    // under Embree's flush-to-zero mode, and its spatial-split builder asserts on that (found
    // by fuzzing: a vertex coordinate of 4e-38 aborted the BVH build).
    Vec3 p = positions[i];
    for (int k = 0; k < 3; ++k)
      if (std::abs(p[k]) < 1e-30f) p[k] = 0.0f;
    positions_.push_back(p);
    normals_.push_back(smooth ? glm::normalize(normals[i]) : Vec3(0.0f));
    uvs_.push_back(uvs.empty() ? Vec2(0.0f) : uvs[i]);
    bounds_.extend(p);
  }
  for (size_t i = 0; i < indices.size(); i += 3) {
    Triangle tri;
    for (int k = 0; k < 3; ++k) {
      if (indices[i + k] >= positions.size()) throw Error("mesh index out of range");
      tri.v[k] = base + indices[i + k];
    }
    tri.material = material;
    tri.smooth = smooth;
    tri.hasUV = !uvs.empty();
    tri.hasTangent = materials_[material].normalMap && !uvs.empty();
    triangles_.push_back(tri);
  }
  if (!materials_[material].normalMap || uvs.empty()) return;
  // Tangents for the normal map. Given (glTF TANGENT): as they are. Otherwise per vertex from
  // the uvs, t = ∂p/∂u of each triangle, (Δp₁ Δv₂ − Δp₂ Δv₁)/(Δu₁ Δv₂ − Δu₂ Δv₁), summed over
  // the triangles around it (Lengyel's method), made orthogonal to the normal, with w = +1,
  // bitangent n × t: what the Khronos glTF sample viewer does for a file without TANGENT.
  tangents_.resize(positions_.size(), glm::vec4(0.0f));
  if (!tangents.empty()) {
    for (size_t i = 0; i < positions.size(); ++i) tangents_[base + i] = tangents[i];
    return;
  }
  std::vector<Vec3> sum(positions.size(), Vec3(0.0f)), faceSum(positions.size(), Vec3(0.0f));
  for (size_t i = 0; i < indices.size(); i += 3) {
    const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    Vec3 dp1 = positions[b] - positions[a], dp2 = positions[c] - positions[a];
    Vec2 duv1 = uvs[b] - uvs[a], duv2 = uvs[c] - uvs[a];
    float det = duv1.x * duv2.y - duv2.x * duv1.y;
    Vec3 n = glm::cross(dp1, dp2);
    for (uint32_t v : {a, b, c}) faceSum[v] += n;
    if (std::abs(det) < 1e-20f) continue;  // degenerate uvs: no direction from this triangle
    Vec3 t = (dp1 * duv2.y - dp2 * duv1.y) / det;
    for (uint32_t v : {a, b, c}) sum[v] += t;
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    Vec3 n = smooth ? normals_[base + i] : faceSum[i];
    float nl = glm::length(n);
    n = nl > 0 ? n / nl : Vec3(0, 0, 1);
    Vec3 t = sum[i] - n * glm::dot(n, sum[i]);
    float tl = glm::length(t);
    tangents_[base + i] = tl > 0 ? glm::vec4(t / tl, 1.0f) : glm::vec4(0.0f);
  }
}

void Scene::addLight(std::unique_ptr<Light> light) {
  if (light->isInfinite()) {
    if (environment_) throw Error("a scene has at most one environment light");
    environment_ = static_cast<const EnvironmentLight*>(light.get());
    environmentIndex_ = int(lights_.size());
  }
  lights_.push_back(std::move(light));
}

void Scene::commit() {
  if (committed_) throw Error("scene committed twice");
  committed_ = true;
  if (bounds_.empty()) bounds_.extend(Vec3(0.0f));
  // Offsets scale with the scene so metre- and millimetre-sized scenes both avoid self-hits.
  epsilon_ = std::max(1e-6f, kRayEpsilonScale * std::max(1.0f, 2.0f * bounds_.radius()));

  faceNormals_.resize(triangles_.size());
  for (size_t i = 0; i < triangles_.size(); ++i) {
    Triangle& tri = triangles_[i];
    const Vec3 &a = positions_[tri.v[0]], &b = positions_[tri.v[1]], &c = positions_[tri.v[2]];
    Vec3 n = glm::cross(b - a, c - a);
    float len = glm::length(n);
    faceNormals_[i] = len > 0 ? n / len : Vec3(0, 0, 1);
    const Material& m = materials_[tri.material];
    if (!isBlack(m.emission) && len > 0) {
      std::unique_ptr<AreaLight> light;
      if (m.emissionTexture) {
        auto texture = std::make_shared<EmissionTexture>();
        texture->texture = m.emissionTexture;
        for (int k = 0; k < 3; ++k) texture->uv[k] = tri.hasUV ? uvs_[tri.v[k]] : Vec2(0.0f);
        light = std::make_unique<AreaLight>(a, b, c, m.emission, m.twoSided, std::move(texture));
        if (isBlack(light->meanRadiance())) continue;  // dark texels are not lights
      } else {
        light = std::make_unique<AreaLight>(a, b, c, m.emission, m.twoSided);
      }
      tri.light = int32_t(lights_.size());
      lights_.push_back(std::move(light));
    }
  }

  std::vector<float> weights;
  for (auto& light : lights_) {
    light->preprocess(bounds_.center(), std::max(bounds_.radius(), 1e-3f));
    weights.push_back(std::max(0.0f, average(light->power())));
  }
  lightDistribution_ = AliasTable(weights);

  rtcScene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtcScene_, RTC_BUILD_QUALITY_HIGH);
  // Opaque triangles in one geometry; those whose material has alpha in a second, with the
  // filter, so opaque traversal pays nothing for it.
  std::vector<uint32_t> opaque, cutout;
  for (uint32_t i = 0; i < triangles_.size(); ++i)
    (materials_[triangles_[i].material].alphaMode == AlphaMode::Opaque ? opaque : cutout).push_back(i);
  for (const std::vector<uint32_t>* part : {&opaque, &cutout}) {
    if (part->empty()) continue;
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), positions_.size()));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(uint32_t), part->size()));
    if (!vb || !ib) throw Error("Embree: out of memory for " + std::to_string(triangles_.size()) + " triangles");
    for (size_t i = 0; i < positions_.size(); ++i) {
      vb[3 * i] = positions_[i].x;
      vb[3 * i + 1] = positions_[i].y;
      vb[3 * i + 2] = positions_[i].z;
    }
    for (size_t i = 0; i < part->size(); ++i)
      for (int k = 0; k < 3; ++k) ib[3 * i + k] = triangles_[(*part)[i]].v[k];
    if (part == &cutout) {
      rtcSetGeometryUserData(geom, this);
      rtcSetGeometryIntersectFilterFunction(geom, &Scene::alphaFilter);
      rtcSetGeometryOccludedFilterFunction(geom, &Scene::alphaFilter);
    }
    rtcCommitGeometry(geom);
    unsigned id = rtcAttachGeometry(rtcScene_, geom);
    rtcReleaseGeometry(geom);
    if (geometryTriangles_.size() <= id) geometryTriangles_.resize(id + 1);
    if (part->size() != triangles_.size()) geometryTriangles_[id] = *part;
  }
  rtcCommitScene(rtcScene_);
  RTCError err = rtcGetDeviceError(device_);
  if (err != RTC_ERROR_NONE) throw Error("Embree: BVH build failed (error " + std::to_string(int(err)) + ")");
}

Spectrum Scene::totalPower() const {
  Spectrum sum(0.0f);
  for (auto& light : lights_) sum += light->power();
  return sum;
}

namespace {
// What Embree accepts (RayK::valid(): |components| ≤ FLT_LARGE = 1.844e18, no NaN). Debian's
// Embree asserts on anything else and aborts the process; a ray that overflowed is a miss
// for intersect() and blocked for occluded() instead.
bool embreeValid(const Ray& r) {
  constexpr float kLarge = 1.844e18f;
  // One comparison for all six components (this runs for every ray): their magnitudes' sum is
  // NaN if any is NaN and exceeds kLarge if any does (slightly stricter than Embree, which is
  // harmless: the loader bounds scenes at 1e7 m).
  float sum = std::abs(r.o.x) + std::abs(r.o.y) + std::abs(r.o.z) + std::abs(r.d.x) + std::abs(r.d.y) + std::abs(r.d.z);
  return sum <= kLarge && r.tmin >= 0.0f && !(r.tmax != r.tmax);
}
}  // namespace

bool Scene::intersect(const Ray& ray, SurfaceHit* hit) const {
  if (!embreeValid(ray)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = ray.o.x;
  rh.ray.org_y = ray.o.y;
  rh.ray.org_z = ray.o.z;
  rh.ray.dir_x = ray.d.x;
  rh.ray.dir_y = ray.d.y;
  rh.ray.dir_z = ray.d.z;
  rh.ray.tnear = ray.tmin;
  rh.ray.tfar = ray.tmax;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;  // a zero mask hits nothing
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rtcScene_, &context, &rh);
  ++rayCounter.count;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  *hit = surfaceAt(triangleOf(rh.hit.geomID, rh.hit.primID), rh.hit.u, rh.hit.v);  // Embree: p = (1 − u − v) v0 + u v1 + v v2
  hit->t = rh.ray.tfar;
  return true;
}

bool Scene::occluded(const Ray& ray) const {
  if (!embreeValid(ray)) return true;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  r.org_x = ray.o.x;
  r.org_y = ray.o.y;
  r.org_z = ray.o.z;
  r.dir_x = ray.d.x;
  r.dir_y = ray.d.y;
  r.dir_z = ray.d.z;
  r.tnear = ray.tmin;
  r.tfar = ray.tmax;
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(rtcScene_, &context, &r);
  ++rayCounter.count;
  return r.tfar < 0.0f;  // Embree sets tfar = −inf when something was hit
}

namespace {
uint64_t mix64(uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30, x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27, x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
uint64_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}
}  // namespace

bool Scene::presentAt(uint32_t triangle, float b1, float b2, uint64_t rayHash) const {
  const Triangle& tri = triangles_[triangle];
  const Material& m = materials_[tri.material];
  Vec2 uv = tri.hasUV ? (1 - b1 - b2) * uvs_[tri.v[0]] + b1 * uvs_[tri.v[1]] + b2 * uvs_[tri.v[2]] : Vec2(0.0f);
  float alpha = m.alpha ? m.alpha->eval(uv) : 1.0f;
  if (m.alphaMode == AlphaMode::Mask) return alpha >= m.alphaCutoff;
  // BLEND: present with probability alpha, decided by a hash of the ray and where it crosses
  // the triangle: deterministic (the same ray decides the same way on any thread), and
  // independent between rays as the sampler's own numbers are.
  uint64_t h = mix64(rayHash ^ mix64(uint64_t(triangle) << 32 ^ bitsOf(b1) << 1 ^ bitsOf(b2)));
  return float(h >> 40) * 0x1p-24f < alpha;
}

void Scene::alphaFilter(const RTCFilterFunctionNArguments* args) {
  const Scene* scene = static_cast<const Scene*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned N = args->N;
    uint64_t ray = mix64(bitsOf(RTCRayN_org_x(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_org_y(args->ray, N, i)));
    ray = mix64(ray ^ bitsOf(RTCRayN_org_z(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_dir_x(args->ray, N, i)));
    ray = mix64(ray ^ bitsOf(RTCRayN_dir_y(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_dir_z(args->ray, N, i)));
    uint32_t triangle = scene->triangleOf(RTCHitN_geomID(args->hit, N, i), RTCHitN_primID(args->hit, N, i));
    if (!scene->presentAt(triangle, RTCHitN_u(args->hit, N, i), RTCHitN_v(args->hit, N, i), ray)) args->valid[i] = 0;
  }
}

SurfaceHit Scene::surfaceAt(uint32_t primitive, float b1, float b2) const {
  const Triangle& tri = triangles_[primitive];
  float b0 = 1.0f - b1 - b2;
  SurfaceHit hit;
  hit.p = b0 * positions_[tri.v[0]] + b1 * positions_[tri.v[1]] + b2 * positions_[tri.v[2]];
  hit.ng = faceNormals_[primitive];
  Vec3 ns = hit.ng;
  if (tri.smooth) {
    Vec3 n = b0 * normals_[tri.v[0]] + b1 * normals_[tri.v[1]] + b2 * normals_[tri.v[2]];
    float len = glm::length(n);
    if (len > 0) ns = n / len;
  }
  hit.uv = tri.hasUV ? b0 * uvs_[tri.v[0]] + b1 * uvs_[tri.v[1]] + b2 * uvs_[tri.v[2]] : Vec2(0.0f);
  if (tri.hasTangent) {
    // Normal map: n = normalize(x t + y b + z ns), b = w ns × t, t the interpolated tangent made
    // orthogonal to ns. A mapped normal on the other side of the surface from ns is not used.
    glm::vec4 t4 = b0 * tangents_[tri.v[0]] + b1 * tangents_[tri.v[1]] + b2 * tangents_[tri.v[2]];
    Vec3 t = Vec3(t4) - ns * glm::dot(ns, Vec3(t4));
    float len = glm::length(t);
    if (len > 0) {
      t /= len;
      Vec3 b = (t4.w < 0 ? -1.0f : 1.0f) * glm::cross(ns, t);
      Vec3 m = materials_[tri.material].normalMap->eval(hit.uv);
      Vec3 mapped = glm::normalize(m.x * t + m.y * b + m.z * ns);
      if (glm::dot(mapped, hit.ng) * glm::dot(ns, hit.ng) > 0) ns = mapped;
    }
  }
  hit.shading = Frame(ns);
  hit.barycentric = Vec2(b1, b2);
  hit.primitive = primitive;
  hit.bsdf = materials_[tri.material].bsdf.get();
  hit.lightIndex = tri.light;
  hit.light = tri.light >= 0 ? static_cast<const AreaLight*>(lights_[tri.light].get()) : nullptr;
  return hit;
}

std::array<Vec3, 3> Scene::trianglePositions(uint32_t primitive) const {
  const Triangle& tri = triangles_[primitive];
  return {positions_[tri.v[0]], positions_[tri.v[1]], positions_[tri.v[2]]};
}

Ray Scene::spawnRay(const SurfaceHit& hit, const Vec3& d) const {
  Vec3 offset = hit.ng * (glm::dot(d, hit.ng) > 0 ? epsilon_ : -epsilon_);
  return Ray{hit.p + offset, d, 0.0f, INFINITY};
}

bool Scene::visible(const SurfaceHit& hit, const Vec3& wi, float distance) const {
  Ray r = spawnRay(hit, wi);
  if (std::isinf(distance)) return !occluded(r);
  // Aim from the offset origin at the sampled light point itself (keeping the unoffset
  // direction would cross the light's own plane before tmax at grazing angles), and stop one
  // epsilon short of it so the light's surface does not occlude itself.
  Vec3 target = hit.p + wi * distance;
  Vec3 d = target - r.o;
  float length = glm::length(d);
  if (length <= 2 * epsilon_) return true;
  r.d = d / length;
  r.tmax = length - epsilon_;
  return !occluded(r);
}

}  // namespace pl
