#include "scene/scene.h"

#include <cstring>

#include "core/ray_counts.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace pl {

uint64_t Scene::raysTraced() { return rays::all(); }
uint64_t Scene::shadowRaysTraced() { return rays::shadow(); }
void Scene::countRays(uint64_t closest, uint64_t shadow) { rays::add(closest + shadow, shadow); }

Scene::Scene() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  prototypes_.emplace_back();  // prototype 0: the world
  instances_.emplace_back();   // instance 0: the world as it is
}

Scene::~Scene() {
  if (rtcScene_) rtcReleaseScene(rtcScene_);
  for (Prototype& p : prototypes_)
    if (p.rtc) rtcReleaseScene(p.rtc);
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
  if (!normals.empty() && normals.size() != positions.size()) throw Error("mesh normal count differs from its positions");
  if (!uvs.empty() && uvs.size() != positions.size()) throw Error("mesh uv count differs from its positions");
  if (!tangents.empty() && tangents.size() != positions.size()) throw Error("mesh tangent count differs from its positions");
  MeshAttributes a;
  a.normals = !normals.empty();
  a.uvs = !uvs.empty();
  a.tangents = !tangents.empty();
  MeshSlot slot = appendMesh(0, positions.size(), indices.size() / 3, material, a);
  std::copy(positions.begin(), positions.end(), slot.positions);
  std::copy(indices.begin(), indices.end(), slot.indices);
  if (slot.normals) std::copy(normals.begin(), normals.end(), slot.normals);
  if (slot.uvs) std::copy(uvs.begin(), uvs.end(), slot.uvs);
  if (slot.tangents && !tangents.empty()) std::copy(tangents.begin(), tangents.end(), slot.tangents);
  finishMesh();
}

uint32_t Scene::addPrototype() {
  if (committed_) throw Error("scene already committed");
  prototypes_.emplace_back();
  return uint32_t(prototypes_.size() - 1);
}

void Scene::addInstance(uint32_t prototype, const Mat4& objectToWorld) {
  if (committed_) throw Error("scene already committed");
  if (prototype == 0 || prototype >= prototypes_.size()) throw Error("instance of an unknown prototype");
  Instance inst;
  inst.prototype = prototype;
  inst.toWorld = objectToWorld;
  inst.linear = glm::mat3(objectToWorld);
  inst.normalMatrix = glm::transpose(glm::inverse(inst.linear));
  inst.mirrors = glm::determinant(inst.linear) < 0;
  instances_.push_back(std::move(inst));
}

namespace {
// Grows v to n elements, keeping one more element's room: Embree reads a shared vertex buffer's
// last vertex with a 16-byte load. Capacity at least doubles, so appends stay linear.
template <typename T>
void growTo(std::vector<T>& v, size_t n) {
  if (v.capacity() < n + 1) v.reserve(std::max(n + 1, 2 * v.capacity()));
  v.resize(n);
}
}  // namespace

void Scene::reserve(uint32_t prototype, size_t vertices, size_t triangles, const MeshAttributes& extra) {
  Prototype& p = prototypes_.at(prototype);
  p.positions.reserve(p.positions.size() + vertices + 1);
  p.indices.reserve(p.indices.size() + 3 * triangles);
  if (extra.normals) p.normals.reserve(p.normals.size() + vertices + 1);
  if (extra.uvs) p.uvs.reserve(p.uvs.size() + vertices + 1);
  if (extra.tangents) p.tangents.reserve(p.tangents.size() + vertices + 1);
  if (extra.colors) p.colors.reserve(p.colors.size() + vertices + 1);
}

MeshSlot Scene::appendMesh(uint32_t prototype, size_t vertices, size_t triangles, uint32_t material,
                           const MeshAttributes& attributes) {
  if (committed_) throw Error("scene already committed");
  if (meshOpen_) throw Error("appendMesh before the previous mesh was finished");
  if (prototype >= prototypes_.size()) throw Error("mesh of an unknown prototype");
  if (material >= materials_.size()) throw Error("mesh refers to an unknown material");
  Prototype& p = prototypes_[prototype];
  if (p.positions.size() + vertices > UINT32_MAX || p.indices.size() / 3 + triangles > UINT32_MAX / 3)
    throw Error("more than 4 billion vertices or triangles in one mesh group");
  Part part;
  part.firstVertex = uint32_t(p.positions.size());
  part.vertexCount = uint32_t(vertices);
  part.firstTriangle = uint32_t(p.indices.size() / 3);
  part.triangleCount = uint32_t(triangles);
  part.material = material;
  MeshSlot slot;
  slot.vertices = vertices;
  slot.triangles = triangles;
  growTo(p.positions, p.positions.size() + vertices);
  growTo(p.indices, p.indices.size() + 3 * triangles);
  p.triangles += uint32_t(triangles);
  slot.positions = p.positions.data() + part.firstVertex;
  slot.indices = p.indices.data() + 3 * size_t(part.firstTriangle);
  if (attributes.normals) {
    part.firstNormal = int64_t(p.normals.size());
    growTo(p.normals, p.normals.size() + vertices);
    slot.normals = p.normals.data() + part.firstNormal;
  }
  if (attributes.uvs) {
    part.firstUV = int64_t(p.uvs.size());
    growTo(p.uvs, p.uvs.size() + vertices);
    slot.uvs = p.uvs.data() + part.firstUV;
  }
  if (attributes.colors) {
    part.firstColor = int64_t(p.colors.size());
    growTo(p.colors, p.colors.size() + vertices);
    slot.colors = p.colors.data() + part.firstColor;
  }
  // Tangents matter only to a normal-mapped material with texture coordinates: stored for those
  // alone, given (slot.tangents to fill) or generated by finishMesh().
  if (materials_[material].normalMap && attributes.uvs) {
    part.firstTangent = int64_t(p.tangents.size());
    growTo(p.tangents, p.tangents.size() + vertices);
    if (attributes.tangents) slot.tangents = p.tangents.data() + part.firstTangent;
    else std::fill(p.tangents.begin() + part.firstTangent, p.tangents.end(), glm::vec4(-2.0f));  // marks "generate"
  }
  p.parts.push_back(part);
  meshOpen_ = true;
  lastPrototype_ = prototype;
  return slot;
}

void Scene::finishMesh() {
  if (!meshOpen_) throw Error("finishMesh without appendMesh");
  meshOpen_ = false;
  Prototype& proto = prototypes_[lastPrototype_];
  const Part& part = proto.parts.back();
  Vec3* positions = proto.positions.data() + part.firstVertex;
  const uint32_t* indices = proto.indices.data() + 3 * size_t(part.firstTriangle);
  const size_t n = part.vertexCount;
  for (size_t i = 0; i < 3 * size_t(part.triangleCount); ++i)
    if (indices[i] >= n) throw Error("mesh index out of range");
  Bounds& bounds = lastPrototype_ == 0 ? bounds_ : proto.bounds;
  for (size_t i = 0; i < n; ++i) {
    // Coordinates within 1e-30 m of zero are zero. Differences of values near FLT_MIN underflow
    // under Embree's flush-to-zero mode, and its spatial-split builder asserts on that (found
    // by fuzzing: a vertex coordinate of 4e-38 aborted the BVH build).
    Vec3& p = positions[i];
    for (int k = 0; k < 3; ++k)
      if (std::abs(p[k]) < 1e-30f) p[k] = 0.0f;
    bounds.extend(p);
  }
  Vec3* normals = part.firstNormal >= 0 ? proto.normals.data() + part.firstNormal : nullptr;
  if (normals)
    for (size_t i = 0; i < n; ++i) normals[i] = glm::normalize(normals[i]);
  if (part.firstTangent < 0) return;
  glm::vec4* tangents = proto.tangents.data() + part.firstTangent;
  if (n == 0 || tangents[0] != glm::vec4(-2.0f)) return;  // given (glTF TANGENT): as they are
  // Tangents for the normal map, per vertex from the uvs: t = ∂p/∂u of each triangle,
  // (Δp₁ Δv₂ − Δp₂ Δv₁)/(Δu₁ Δv₂ − Δu₂ Δv₁), summed over the triangles around it (Lengyel's
  // method), made orthogonal to the normal, with w = +1, bitangent n × t: what the Khronos glTF
  // sample viewer does for a file without TANGENT.
  const Vec2* uvs = proto.uvs.data() + part.firstUV;
  std::vector<Vec3> sum(n, Vec3(0.0f)), faceSum(n, Vec3(0.0f));
  for (size_t i = 0; i < 3 * size_t(part.triangleCount); i += 3) {
    const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    Vec3 dp1 = positions[b] - positions[a], dp2 = positions[c] - positions[a];
    Vec2 duv1 = uvs[b] - uvs[a], duv2 = uvs[c] - uvs[a];
    float det = duv1.x * duv2.y - duv2.x * duv1.y;
    Vec3 fn = glm::cross(dp1, dp2);
    for (uint32_t v : {a, b, c}) faceSum[v] += fn;
    if (std::abs(det) < 1e-20f) continue;  // degenerate uvs: no direction from this triangle
    Vec3 t = (dp1 * duv2.y - dp2 * duv1.y) / det;
    for (uint32_t v : {a, b, c}) sum[v] += t;
  }
  for (size_t i = 0; i < n; ++i) {
    Vec3 nn = normals ? normals[i] : faceSum[i];
    float nl = glm::length(nn);
    nn = nl > 0 ? nn / nl : Vec3(0, 0, 1);
    Vec3 t = sum[i] - nn * glm::dot(nn, sum[i]);
    float tl = glm::length(t);
    tangents[i] = tl > 0 ? glm::vec4(t / tl, 1.0f) : glm::vec4(0.0f);
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

size_t Scene::storedTriangleCount() const {
  size_t n = 0;
  for (const Prototype& p : prototypes_) n += p.triangleCount();
  return n;
}

size_t Scene::pairedTriangleCount() const {
  size_t n = 0;
  for (const Prototype& p : prototypes_)
    for (const Part& part : p.parts) n += 2 * size_t(part.pairs);
  return n;
}

// One AreaLight per emissive triangle of the instance's prototype, in world space (a mirroring
// instance's corners in swapped order, so that the light faces where its triangle does).
void Scene::createAreaLights(Instance& inst) {
  const Prototype& proto = prototypes_[inst.prototype];
  inst.lights.assign(proto.parts.size(), {});
  for (size_t pi = 0; pi < proto.parts.size(); ++pi) {
    const Part& part = proto.parts[pi];
    const Material& m = materials_[part.material];
    if (isBlack(m.emission)) continue;
    std::vector<int32_t>& lights = inst.lights[pi];
    lights.assign(part.triangleCount, -1);
    for (uint32_t t = 0; t < part.triangleCount; ++t) {
      const std::array<uint32_t, 3> idx = corners(proto, part, t);
      uint32_t v[3] = {part.firstVertex + idx[0], part.firstVertex + idx[1], part.firstVertex + idx[2]};
      if (inst.mirrors) std::swap(v[1], v[2]);
      Vec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = inst.prototype == 0 ? proto.positions[v[k]] : Vec3(inst.toWorld * glm::vec4(proto.positions[v[k]], 1.0f));
      if (!(glm::length(glm::cross(p[1] - p[0], p[2] - p[0])) > 0)) continue;
      std::unique_ptr<AreaLight> light;
      if (m.emissionTexture) {
        auto texture = std::make_shared<EmissionTexture>();
        texture->texture = m.emissionTexture;
        for (int k = 0; k < 3; ++k)
          texture->uv[k] = part.firstUV >= 0 ? proto.uvs[size_t(part.firstUV) + v[k] - part.firstVertex] : Vec2(0.0f);
        light = std::make_unique<AreaLight>(p[0], p[1], p[2], m.emission, m.twoSided, std::move(texture));
        if (isBlack(light->meanRadiance())) continue;  // dark texels are not lights
      } else {
        light = std::make_unique<AreaLight>(p[0], p[1], p[2], m.emission, m.twoSided);
      }
      lights[t] = int32_t(lights_.size());
      lights_.push_back(std::move(light));
    }
  }
}

// The prototype's parts as Embree geometries with IDs = part indices, in `into` (the top-level
// scene for the world) or in a scene of their own; they share the prototype's arrays.
RTCScene Scene::buildEmbreeScene(uint32_t prototype, RTCScene into) {
  Prototype& proto = prototypes_[prototype];
  for (uint32_t pi = 0; pi < proto.parts.size(); ++pi) {
    const Part& part = proto.parts[pi];
    if (part.triangleCount == 0) continue;  // its ID stays unused
    RTCGeometry geom = rtcNewGeometry(device_, proto.paired ? RTC_GEOMETRY_TYPE_QUAD : RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, proto.positions.data(),
                               size_t(part.firstVertex) * sizeof(Vec3), sizeof(Vec3), part.vertexCount);
    if (proto.paired)
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, proto.quads.data(),
                                 size_t(part.firstQuad) * 4 * sizeof(uint32_t), 4 * sizeof(uint32_t),
                                 part.triangleCount - part.pairs);
    else
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, proto.indices.data(),
                                 size_t(part.firstTriangle) * 3 * sizeof(uint32_t), 3 * sizeof(uint32_t), part.triangleCount);
    const Material& material = materials_[part.material];
    if (material.alphaMode != AlphaMode::Opaque && (material.alpha || part.firstColor >= 0)) {
      filterData_.push_back({this, prototype, pi});
      rtcSetGeometryUserData(geom, &filterData_.back());
      rtcSetGeometryIntersectFilterFunction(geom, &Scene::alphaFilter);
      rtcSetGeometryOccludedFilterFunction(geom, &Scene::alphaFilter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(into, geom, pi);
    rtcReleaseGeometry(geom);
  }
  return into;
}

void Scene::commit() {
  if (committed_) throw Error("scene committed twice");
  if (meshOpen_) throw Error("commit before the last mesh was finished");
  committed_ = true;
  // Instances: numbered triangles and bounds (their prototype's box, transformed).
  uint32_t nextPrimitive = prototypes_[0].triangleCount();
  for (size_t i = 1; i < instances_.size(); ++i) {
    Instance& inst = instances_[i];
    const Prototype& proto = prototypes_[inst.prototype];
    inst.firstPrimitive = nextPrimitive;
    if (uint64_t(nextPrimitive) + proto.triangleCount() > UINT32_MAX) throw Error("more than 4 billion triangles in the scene");
    nextPrimitive += proto.triangleCount();
    if (proto.bounds.empty()) continue;
    for (int c = 0; c < 8; ++c) {
      Vec3 corner((c & 1) ? proto.bounds.hi.x : proto.bounds.lo.x, (c & 2) ? proto.bounds.hi.y : proto.bounds.lo.y,
                  (c & 4) ? proto.bounds.hi.z : proto.bounds.lo.z);
      bounds_.extend(Vec3(inst.toWorld * glm::vec4(corner, 1.0f)));
    }
  }
  triangleCount_ = nextPrimitive;
  if (bounds_.empty()) bounds_.extend(Vec3(0.0f));
  // Offsets scale with the scene so metre- and millimetre-sized scenes both avoid self-hits.
  epsilon_ = std::max(1e-6f, kRayEpsilonScale * std::max(1.0f, 2.0f * bounds_.radius()));

  compact_ = bvhLayout_ == BvhLayout::Compact || (bvhLayout_ == BvhLayout::Auto && storedTriangleCount() >= kCompactTriangles);
  for (Prototype& proto : prototypes_) {
    if (compact_) {
      pairIntoQuads(proto);
      continue;
    }
    // The default layout keeps each triangle's unit normal (12 bytes a triangle): computing it
    // per hit put a square root and three divisions on every ray's critical path.
    proto.faceNormals.resize(proto.triangleCount());
    for (const Part& part : proto.parts) {
      const Vec3* P = proto.positions.data() + part.firstVertex;
      for (uint32_t t = 0; t < part.triangleCount; ++t) {
        const std::array<uint32_t, 3> idx = corners(proto, part, t);
        proto.faceNormals[part.firstTriangle + t] = faceNormal(P[idx[0]], P[idx[1]], P[idx[2]]);
      }
    }
  }

  for (Instance& inst : instances_) createAreaLights(inst);
  for (const Material& m : materials_) absorbing_ |= m.absorbs();

  std::vector<float> weights;
  for (auto& light : lights_) {
    light->preprocess(bounds_.center(), std::max(bounds_.radius(), 1e-3f));
    weights.push_back(std::max(0.0f, average(light->power())));
  }
  lightDistribution_ = AliasTable(weights);

  auto newScene = [&] {
    RTCScene scene = rtcNewScene(device_);
    // The compact layout (index-referencing leaves, triangles paired into quads) takes less than
    // half the BVH's memory; with it the medium-quality build, whose peak memory is the compact
    // tree's own (docs: reference/gltf.md, Large files). Robust mode: Embree's quad test is not watertight
    // along a quad's diagonal without it (rays through it missed both halves); its Plücker test is.
    if (compact_) rtcSetSceneFlags(scene, RTCSceneFlags(RTC_SCENE_FLAG_COMPACT | RTC_SCENE_FLAG_ROBUST));
    rtcSetSceneBuildQuality(scene, compact_ ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);
    return scene;
  };
  rtcScene_ = buildEmbreeScene(0, newScene());
  const unsigned firstInstanceID = unsigned(prototypes_[0].parts.size());
  for (size_t i = 1; i < instances_.size(); ++i) {
    Prototype& proto = prototypes_[instances_[i].prototype];
    if (!proto.rtc) {
      proto.rtc = buildEmbreeScene(instances_[i].prototype, newScene());
      rtcCommitScene(proto.rtc);
    }
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(geom, proto.rtc);
    rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &instances_[i].toWorld[0][0]);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(rtcScene_, geom, unsigned(firstInstanceID + i - 1));
    rtcReleaseGeometry(geom);
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
  rays::add(1, 0);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hitOf(rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, hit);
  return true;
}

void Scene::hitOf(unsigned instID, unsigned geomID, uint32_t primID, float u, float v, float t, SurfaceHit* hit) const {
  // Embree: p = (1 − u − v) v0 + u v1 + v v2. A hit inside an instance names the instance's
  // geometry in instID[0] and the part within its prototype in geomID.
  const Instance& inst = instID == RTC_INVALID_GEOMETRY_ID ? instances_[0]
                                                           : instances_[instID - prototypes_[0].parts.size() + 1];
  const Prototype& proto = prototypes_[inst.prototype];
  float b1 = u, b2 = v;
  triangleOfHit(proto, proto.parts[geomID], &primID, &b1, &b2);
  surfaceOf(inst, geomID, primID, b1, b2, hit);
  hit->t = t;
}

namespace {
// The packet's lanes that go to Embree: active, and a ray Embree accepts. Returns how many.
int packetLanes(const Ray* rays, const bool* active, int* valid, int* only) {
  int n = 0;
  for (int k = 0; k < Scene::kPacket; ++k) {
    valid[k] = active[k] && embreeValid(rays[k]) ? -1 : 0;
    if (valid[k]) n++, *only = k;
  }
  return n;
}

void fillLane(RTCRay8& r, int k, const Ray& ray) {
  r.org_x[k] = ray.o.x, r.org_y[k] = ray.o.y, r.org_z[k] = ray.o.z;
  r.dir_x[k] = ray.d.x, r.dir_y[k] = ray.d.y, r.dir_z[k] = ray.d.z;
  r.tnear[k] = ray.tmin, r.tfar[k] = ray.tmax, r.time[k] = 0.0f;
  r.mask[k] = 0xFFFFFFFFu, r.id[k] = 0, r.flags[k] = 0;
}
}  // namespace

void Scene::intersect(const Ray* rays, const bool* active, bool coherent, SurfaceHit* hits, bool* found) const {
  alignas(32) int valid[kPacket];
  int only = 0;
  const int n = packetLanes(rays, active, valid, &only);
  for (int k = 0; k < kPacket; ++k) found[k] = false;
  if (n == 1) {  // a packet of one costs more than the one-ray query
    found[only] = intersect(rays[only], &hits[only]);
    return;
  }
  if (n == 0) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRayHit8 rh;
  for (int k = 0; k < kPacket; ++k) {
    // An inactive lane gets a finite ray with tfar < tnear, not uninitialised values: Embree
    // checks the lanes it deems active by their rays as well as by the mask.
    if (!valid[k]) {
      fillLane(rh.ray, k, Ray{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f), 0.0f, -INFINITY});
      continue;
    }
    fillLane(rh.ray, k, rays[k]);
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect8(valid, rtcScene_, &context, &rh);
  rays::add(uint64_t(n), 0);
  for (int k = 0; k < kPacket; ++k) {
    if (!valid[k] || rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
    found[k] = true;
    hitOf(rh.hit.instID[0][k], rh.hit.geomID[k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k], rh.ray.tfar[k], &hits[k]);
  }
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
  rays::add(1, 1);
  return r.tfar < 0.0f;  // Embree sets tfar = −inf when something was hit
}

namespace {
constexpr uint32_t kUnpaired = UINT32_MAX;

// Triangle t's corners run the directed edge a -> b: the triangle across from it, b -> a on a
// consistently oriented mesh, faces the same way.
bool runsEdge(const uint32_t* c, uint32_t a, uint32_t b) {
  return (c[0] == a && c[1] == b) || (c[1] == a && c[2] == b) || (c[2] == a && c[0] == b);
}
bool distinctCorners(const uint32_t* c) { return c[0] != c[1] && c[1] != c[2] && c[0] != c[2]; }
uint32_t oppositeCorner(const uint32_t* c, uint32_t a, uint32_t b) {
  return c[0] != a && c[0] != b ? c[0] : c[1] != a && c[1] != b ? c[1] : c[2];
}
// Triangles t and s (corners c, d) make a quad across c's edge k, c[k] -> c[k+1]: s runs it
// backwards and its third corner is not t's (which would fold s onto t).
bool pairsAcross(const uint32_t* c, int k, const uint32_t* d) {
  const uint32_t a = c[k], b = c[(k + 1) % 3];
  return runsEdge(d, b, a) && oppositeCorner(d, a, b) != c[(k + 2) % 3];
}

// Greedy matching of a mesh's n triangles (corners tri, 3 per triangle, into `vertices`
// positions P) across shared edges: partner[t] = the triangle t pairs with, or kUnpaired.
// Triangles are taken in order, each pairing with an unpaired neighbour across its longest edge
// that has one, so a quad mesh's triangles pair across their diagonals, back into its quads.
// Returns the number of pairs.
uint32_t matchTriangles(const uint32_t* tri, uint32_t n, uint32_t vertices, const Vec3* P, uint32_t* partner) {
  // The triangles around each vertex, compressed rows: around[start[v] .. start[v+1]).
  std::vector<uint32_t> start(size_t(vertices) + 1, 0), around(3 * size_t(n));
  for (size_t i = 0; i < 3 * size_t(n); ++i) ++start[tri[i] + 1];
  for (size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
  for (uint32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) around[start[tri[3 * size_t(t) + k]]++] = t;
  for (size_t v = vertices; v > 0; --v) start[v] = start[v - 1];  // filling moved each row's start to the next
  start[0] = 0;

  uint32_t pairs = 0;
  for (uint32_t t = 0; t < n; ++t) {
    const uint32_t* c = tri + 3 * size_t(t);
    if (partner[t] != kUnpaired || !distinctCorners(c)) continue;
    float length[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = P[c[(k + 1) % 3]] - P[c[k]];
      length[k] = glm::dot(e, e);
    }
    int order[3] = {0, 1, 2};
    std::stable_sort(order, order + 3, [&](int i, int j) { return length[i] > length[j]; });
    for (int k : order) {
      const uint32_t b = c[(k + 1) % 3];
      for (uint32_t i = start[b]; i < start[b + 1] && partner[t] == kUnpaired; ++i) {
        const uint32_t s = around[i];
        const uint32_t* d = tri + 3 * size_t(s);
        if (s == t || partner[s] != kUnpaired || !distinctCorners(d) || !pairsAcross(c, k, d)) continue;
        partner[t] = s, partner[s] = t;
        ++pairs;
      }
      if (partner[t] != kUnpaired) break;
    }
  }
  return pairs;
}
}  // namespace

void Scene::pairIntoQuads(Prototype& proto) {
  std::vector<uint32_t> partner(proto.triangles, kUnpaired);
  size_t quads = 0;
  for (Part& part : proto.parts) {
    const uint32_t* tri = proto.indices.data() + 3 * size_t(part.firstTriangle);
    part.pairs = matchTriangles(tri, part.triangleCount, part.vertexCount, proto.positions.data() + part.firstVertex,
                                partner.data() + part.firstTriangle);
    part.firstQuad = uint32_t(quads);
    quads += part.triangleCount - part.pairs;
  }
  proto.quads.resize(4 * quads);
  for (const Part& part : proto.parts) {
    const uint32_t* tri = proto.indices.data() + 3 * size_t(part.firstTriangle);
    const uint32_t* mate = partner.data() + part.firstTriangle;
    uint32_t* q = proto.quads.data() + 4 * size_t(part.firstQuad);
    // Pairs first, in the order of their first triangles: t = (c0, c1, c2) meets s across
    // c[k] -> c[k+1], and the quad (c[k+2], c[k], o, c[k+1]) has t and s as its halves
    // (v0, v1, v3) and (v2, v3, v1), each a rotation of the file's corners (same facing).
    for (uint32_t t = 0; t < part.triangleCount; ++t) {
      if (mate[t] == kUnpaired || mate[t] < t) continue;
      const uint32_t* c = tri + 3 * size_t(t);
      const uint32_t* d = tri + 3 * size_t(mate[t]);
      int k = 0;
      while (!pairsAcross(c, k, d)) ++k;
      const uint32_t a = c[k], b = c[(k + 1) % 3];
      q[0] = c[(k + 2) % 3], q[1] = a, q[2] = oppositeCorner(d, a, b), q[3] = b;
      q += 4;
    }
    // Then every triangle left single, as the quad (c0, c1, c2, c2).
    for (uint32_t t = 0; t < part.triangleCount; ++t) {
      if (mate[t] != kUnpaired) continue;
      const uint32_t* c = tri + 3 * size_t(t);
      q[0] = c[0], q[1] = c[1], q[2] = c[2], q[3] = c[2];
      q += 4;
    }
  }
  std::vector<uint32_t>().swap(proto.indices);
  proto.paired = true;
}

PL_HOT_INLINE std::array<uint32_t, 3> Scene::corners(const Prototype& proto, const Part& part, uint32_t primID) {
  if (!proto.paired) {
    const uint32_t* c = &proto.indices[3 * (size_t(part.firstTriangle) + primID)];
    return {c[0], c[1], c[2]};
  }
  if (primID >= 2 * part.pairs) {
    const uint32_t* q = &proto.quads[4 * (size_t(part.firstQuad) + part.pairs + (primID - 2 * part.pairs))];
    return {q[0], q[1], q[2]};
  }
  const uint32_t* q = &proto.quads[4 * (size_t(part.firstQuad) + primID / 2)];
  return primID & 1 ? std::array<uint32_t, 3>{q[2], q[3], q[1]} : std::array<uint32_t, 3>{q[0], q[1], q[3]};
}

void Scene::triangleOfHit(const Prototype& proto, const Part& part, uint32_t* primID, float* b1, float* b2) {
  if (!proto.paired) return;
  const uint32_t quad = *primID;
  if (quad >= part.pairs) {  // a single triangle (a, b, c, c): Embree hits its half (a, b, c)
    *primID = 2 * part.pairs + (quad - part.pairs);
    return;
  }
  // Embree's quad coordinates: (u, v) on the half (v0, v1, v3), where u + v ≤ 1; the half
  // (v2, v3, v1)'s own (u', v') reported as (1 − u', 1 − v'), so that u + v > 1 there. On the
  // diagonal both halves hold the point.
  if (*b1 + *b2 <= 1.0f) {
    *primID = 2 * quad;
  } else {
    *primID = 2 * quad + 1;
    *b1 = 1.0f - *b1, *b2 = 1.0f - *b2;
  }
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

bool Scene::presentAt(const Prototype& proto, const Part& part, uint32_t primID, float b1, float b2,
                      uint64_t rayHash) const {
  const Material& m = materials_[part.material];
  const uint32_t triangle = part.firstTriangle + primID;
  const std::array<uint32_t, 3> idx = corners(proto, part, primID);
  Vec2 uv(0.0f);
  if (part.firstUV >= 0) {
    const Vec2* uvs = proto.uvs.data() + part.firstUV;
    uv = (1 - b1 - b2) * uvs[idx[0]] + b1 * uvs[idx[1]] + b2 * uvs[idx[2]];
  }
  float alpha = m.alpha ? m.alpha->eval(uv) : 1.0f;
  if (part.firstColor >= 0) {  // COLOR_0's alpha multiplies the coverage
    const glm::vec4* C = proto.colors.data() + part.firstColor;
    alpha *= (1 - b1 - b2) * C[idx[0]].a + b1 * C[idx[1]].a + b2 * C[idx[2]].a;
  }
  if (m.alphaMode == AlphaMode::Mask) return alpha >= m.alphaCutoff;
  // BLEND: present with probability alpha, decided by a hash of the ray and where it crosses
  // the triangle: deterministic (the same ray decides the same way on any thread), and
  // independent between rays as the sampler's own numbers are.
  uint64_t h = mix64(rayHash ^ mix64(uint64_t(triangle) << 32 ^ bitsOf(b1) << 1 ^ bitsOf(b2)));
  return float(h >> 40) * 0x1p-24f < alpha;
}

void Scene::alphaFilter(const RTCFilterFunctionNArguments* args) {
  const FilterData& data = *static_cast<const FilterData*>(args->geometryUserPtr);
  const Prototype& proto = data.scene->prototypes_[data.prototype];
  const Part& part = proto.parts[data.part];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned N = args->N;
    uint64_t ray = mix64(bitsOf(RTCRayN_org_x(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_org_y(args->ray, N, i)));
    ray = mix64(ray ^ bitsOf(RTCRayN_org_z(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_dir_x(args->ray, N, i)));
    ray = mix64(ray ^ bitsOf(RTCRayN_dir_y(args->ray, N, i)) << 32 ^ bitsOf(RTCRayN_dir_z(args->ray, N, i)));
    uint32_t primID = RTCHitN_primID(args->hit, N, i);
    float b1 = RTCHitN_u(args->hit, N, i), b2 = RTCHitN_v(args->hit, N, i);
    triangleOfHit(proto, part, &primID, &b1, &b2);
    if (!data.scene->presentAt(proto, part, primID, b1, b2, ray))
      args->valid[i] = 0;
  }
}

void Scene::surfaceOf(const Instance& inst, uint32_t partIndex, uint32_t primID, float b1, float b2, SurfaceHit* out) const {
  const Prototype& proto = prototypes_[inst.prototype];
  const Part& part = proto.parts[partIndex];
  const uint32_t triangle = part.firstTriangle + primID;
  const std::array<uint32_t, 3> idx = corners(proto, part, primID);
  const Vec3* P = proto.positions.data() + part.firstVertex;
  const Vec3 &a = P[idx[0]], &b = P[idx[1]], &c = P[idx[2]];
  const bool placed = inst.prototype != 0;  // an instance: object space to world space
  float b0 = 1.0f - b1 - b2;
  // Written in place, every field once (a SurfaceHit is 128 bytes, one per ray: no
  // default-constructed copy first).
  SurfaceHit& hit = *out;
  hit.t = INFINITY;
  hit.p = b0 * a + b1 * b + b2 * c;
  hit.ng = proto.faceNormals.empty() ? faceNormal(a, b, c) : proto.faceNormals[triangle];
  // Normals take the inverse transpose; a mirroring instance's front face stays the object's
  // counter-clockwise one (the loader swaps world-space triangles' corners for the same reason).
  if (placed) {
    hit.p = Vec3(inst.toWorld * glm::vec4(hit.p, 1.0f));
    hit.ng = glm::normalize(inst.normalMatrix * hit.ng);
  }
  Vec3 ns = hit.ng;
  if (part.firstNormal >= 0) {
    const Vec3* N = proto.normals.data() + part.firstNormal;
    Vec3 sn = b0 * N[idx[0]] + b1 * N[idx[1]] + b2 * N[idx[2]];
    if (placed) sn = inst.normalMatrix * sn;
    float l = glm::length(sn);
    if (l > 0) ns = sn / l;
  }
  hit.uv = Vec2(0.0f);
  if (part.firstUV >= 0) {
    const Vec2* uv = proto.uvs.data() + part.firstUV;
    hit.uv = b0 * uv[idx[0]] + b1 * uv[idx[1]] + b2 * uv[idx[2]];
  }
  hit.color = Spectrum(1.0f);
  if (part.firstColor >= 0) {
    const glm::vec4* C = proto.colors.data() + part.firstColor;
    hit.color = Spectrum(b0 * C[idx[0]] + b1 * C[idx[1]] + b2 * C[idx[2]]);
  }
  if (part.firstTangent >= 0) {
    // Normal map: n = normalize(x t + y b + z ns), b = w ns × t, t the interpolated tangent made
    // orthogonal to ns. A mapped normal on the other side of the surface from ns is not used.
    const glm::vec4* T = proto.tangents.data() + part.firstTangent;
    glm::vec4 t4 = b0 * T[idx[0]] + b1 * T[idx[1]] + b2 * T[idx[2]];
    Vec3 t3 = Vec3(t4);
    float w = t4.w < 0 ? -1.0f : 1.0f;
    if (placed) t3 = inst.linear * t3, w = inst.mirrors ? -w : w;
    Vec3 t = t3 - ns * glm::dot(ns, t3);
    float tl = glm::length(t);
    if (tl > 0) {
      t /= tl;
      Vec3 bt = w * glm::cross(ns, t);
      Vec3 m = materials_[part.material].normalMap->eval(hit.uv);
      Vec3 mapped = glm::normalize(m.x * t + m.y * bt + m.z * ns);
      if (glm::dot(mapped, hit.ng) * glm::dot(ns, hit.ng) > 0) ns = mapped;
    }
  }
  hit.shading = Frame(ns);
  // Barycentrics in the order trianglePositions() gives the corners (swapped with them for a
  // mirroring instance).
  hit.barycentric = inst.mirrors ? Vec2(b2, b1) : Vec2(b1, b2);
  hit.primitive = inst.firstPrimitive + triangle;
  hit.bsdf = materials_[part.material].bsdf.get();
  hit.material = &materials_[part.material];
  const std::vector<int32_t>& lights = inst.lights[partIndex];
  hit.lightIndex = lights.empty() ? -1 : lights[primID];
  hit.light = hit.lightIndex >= 0 ? static_cast<const AreaLight*>(lights_[size_t(hit.lightIndex)].get()) : nullptr;
}

void Scene::locate(uint32_t primitive, uint32_t* instance, uint32_t* part, uint32_t* primID) const {
  if (primitive >= triangleCount_) throw Error("triangle " + std::to_string(primitive) + " out of range");
  // The last instance whose numbers start at or before `primitive` (instance 0 starts at 0).
  auto it = std::upper_bound(instances_.begin(), instances_.end(), primitive,
                             [](uint32_t p, const Instance& i) { return p < i.firstPrimitive; });
  *instance = uint32_t(it - instances_.begin() - 1);
  const Instance& inst = instances_[*instance];
  const std::vector<Part>& parts = prototypes_[inst.prototype].parts;
  const uint32_t local = primitive - inst.firstPrimitive;
  auto pt = std::upper_bound(parts.begin(), parts.end(), local, [](uint32_t t, const Part& p) { return t < p.firstTriangle; });
  // Parts without triangles share their successor's start: take the last part that holds `local`.
  *part = uint32_t(pt - parts.begin() - 1);
  *primID = local - parts[*part].firstTriangle;
}

SurfaceHit Scene::surfaceAt(uint32_t primitive, float b1, float b2) const {
  uint32_t instance, part, primID;
  locate(primitive, &instance, &part, &primID);
  const Instance& inst = instances_[instance];
  SurfaceHit hit;
  if (inst.mirrors) surfaceOf(inst, part, primID, b2, b1, &hit);
  else surfaceOf(inst, part, primID, b1, b2, &hit);
  return hit;
}

std::array<Vec3, 3> Scene::trianglePositions(uint32_t primitive) const {
  uint32_t instance, part, primID;
  locate(primitive, &instance, &part, &primID);
  const Instance& inst = instances_[instance];
  const Prototype& proto = prototypes_[inst.prototype];
  const Part& pt = proto.parts[part];
  const std::array<uint32_t, 3> idx = corners(proto, pt, primID);
  std::array<Vec3, 3> v;
  for (int k = 0; k < 3; ++k) {
    v[k] = proto.positions[pt.firstVertex + idx[k]];
    if (inst.prototype != 0) v[k] = Vec3(inst.toWorld * glm::vec4(v[k], 1.0f));
  }
  if (inst.mirrors) std::swap(v[1], v[2]);
  return v;
}

std::vector<uint32_t> Scene::geometryFirstTriangles() const {
  if (instances_.size() > 1 || prototypes_[0].paired) return {};
  std::vector<uint32_t> first;
  for (const Part& part : prototypes_[0].parts) first.push_back(part.firstTriangle);  // geomID = the part's index
  return first;
}

bool Scene::hasVertexColors() const {
  for (const Prototype& proto : prototypes_)
    for (const Part& part : proto.parts)
      if (part.firstColor >= 0) return true;
  return false;
}

bool Scene::triangleNormals(uint32_t primitive, std::array<Vec3, 3>* normals) const {
  uint32_t instance, part, primID;
  locate(primitive, &instance, &part, &primID);
  const Instance& inst = instances_[instance];
  const Prototype& proto = prototypes_[inst.prototype];
  const Part& pt = proto.parts[part];
  if (pt.firstNormal < 0) return false;
  const std::array<uint32_t, 3> idx = corners(proto, pt, primID);
  std::array<Vec3, 3>& n = *normals;
  for (int k = 0; k < 3; ++k) {
    n[k] = proto.normals[size_t(pt.firstNormal) + idx[k]];
    if (inst.prototype != 0) n[k] = inst.normalMatrix * n[k];
  }
  if (inst.mirrors) std::swap(n[1], n[2]);
  return true;
}

uint32_t Scene::triangleMaterial(uint32_t primitive) const {
  uint32_t instance, part, primID;
  locate(primitive, &instance, &part, &primID);
  return prototypes_[instances_[instance].prototype].parts[part].material;
}

const AreaLight* Scene::triangleLight(uint32_t primitive) const {
  uint32_t instance, part, primID;
  locate(primitive, &instance, &part, &primID);
  const std::vector<int32_t>& lights = instances_[instance].lights[part];
  const int32_t l = lights.empty() ? -1 : lights[primID];
  return l >= 0 ? static_cast<const AreaLight*>(lights_[size_t(l)].get()) : nullptr;
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
