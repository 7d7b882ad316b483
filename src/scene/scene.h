// A scene: triangles in world space on one Embree BVH, their materials, the lights and the
// camera. Built through the add*() calls (by the glTF loader or by tests), then commit().
#pragma once
#include <embree3/rtcore.h>

#include <array>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "bsdfs/bsdf.h"
#include "core/frame.h"
#include "core/sampling.h"
#include "lights/area_light.h"
#include "lights/environment_light.h"
#include "lights/light.h"
#include "scene/camera.h"

namespace pl {

// glTF alphaMode: OPAQUE ignores alpha; MASK is opaque where alpha ≥ alphaCutoff and absent
// elsewhere; BLEND is stochastic transparency, a ray passing with probability 1 − alpha.
enum class AlphaMode { Opaque, Mask, Blend };

struct Material {
  std::string name;
  std::unique_ptr<BSDF> bsdf;
  Spectrum emission{0.0f};  // emitted radiance Le, W/(m²·sr); with a texture, its factor
  bool twoSided = false;    // glTF doubleSided: emits from both faces
  // glTF emissiveTexture × emission (sRGB texels decoded), or null: Le is `emission` everywhere.
  std::shared_ptr<const ColorTexture> emissionTexture = nullptr;
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  // Coverage (MASK, BLEND); null where it is 1 everywhere (then only COLOR_0's alpha can cut).
  std::shared_ptr<const AlphaTexture> alpha = nullptr;
  std::shared_ptr<const NormalMap> normalMap = nullptr;  // glTF normalTexture, or null
  // KHR_materials_volume: the closed surface holds an absorbing medium whose transmittance over
  // attenuationDistance is attenuationColor (Beer–Lambert), the identity when the distance is
  // infinite (the default).
  ColorTexture attenuationColor{Spectrum(1.0f)};
  float attenuationDistance = INFINITY;
  bool absorbs() const { return std::isfinite(attenuationDistance) && attenuationColor.factor() != Spectrum(1.0f); }
};

struct SurfaceHit {
  float t = INFINITY;
  Vec3 p;
  Vec3 ng;       // geometric normal, unit, on the front (counter-clockwise) side
  Frame shading; // shading normal frame (interpolated NORMAL, or ng when the mesh has none)
  Vec2 uv;
  Spectrum color{1.0f};    // glTF COLOR_0 (linear RGB), white without one: multiplies the base colour
  Vec2 barycentric{0.0f};  // (b1, b2): p = (1 − b1 − b2) v0 + b1 v1 + b2 v2 on the triangle
  uint32_t primitive = 0;
  const BSDF* bsdf = nullptr;
  const Material* material = nullptr;
  const AreaLight* light = nullptr;  // non-null on emissive triangles
  int lightIndex = -1;
  // The shading normal is not the geometric one (interpolated NORMAL, a normal map): estimators
  // that mix the two (photon density estimation, light paths) then need their corrections.
  bool shadingDiffers() const { return shading.n != ng; }
};

// Light leaks: at `hit`, the shading normal and the geometric one must agree on whether light
// between world directions wo and wi is reflected (both on one side) or transmitted; a pair they
// disagree about carries nothing, whatever the BSDF says (woLocal, wiLocal: the same in the
// shading frame). For a BSDF that only reflects this is the rule "the geometric sides match".
inline bool sidesAgree(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, const Vec3& woLocal, const Vec3& wiLocal) {
  return (glm::dot(wo, hit.ng) * glm::dot(wi, hit.ng) > 0) == (woLocal.z * wiLocal.z > 0);
}
// The same rule for a direction wi a path has sampled from wo: true when the two normals
// disagree on transmission (a light leak), and the path ends there. A direction in the surface
// counts as reflected.
inline bool leaksLight(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, const Vec3& woLocal, const Vec3& wiLocal) {
  return (glm::dot(wi, hit.ng) * glm::dot(wo, hit.ng) < 0) != (wiLocal.z * woLocal.z < 0);
}

// The BSDF's context at a surface point: its uv and vertex colour.
inline BSDFContext bsdfContext(const SurfaceHit& hit, const SampledWavelengths& lambda = SampledWavelengths::rgb(),
                               TransportMode mode = TransportMode::Radiance) {
  return BSDFContext(hit.uv, lambda, mode, hit.color);
}

struct Bounds {
  Vec3 lo{INFINITY}, hi{-INFINITY};
  void extend(const Vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  bool empty() const { return lo.x > hi.x; }
  Vec3 center() const { return 0.5f * (lo + hi); }
  float radius() const { return 0.5f * glm::length(hi - lo); }
};

// What a mesh carries besides positions and triangles (the glTF attributes photonlab reads).
struct MeshAttributes {
  bool normals = false;   // NORMAL: smooth shading (without it, the face normal)
  bool uvs = false;       // TEXCOORD_0
  bool tangents = false;  // TANGENT (xyz, w = the bitangent's sign); generated from the uvs when a
                          // normal-mapped mesh has none
  bool colors = false;    // COLOR_0 (linear RGBA): multiplies the base colour and its alpha
};

// A mesh's storage, filled in place by whoever builds it (Scene::appendMesh): `vertices`
// positions (and normals, uvs, tangents where asked for) and 3 indices per triangle.
struct MeshSlot {
  Vec3* positions = nullptr;
  Vec3* normals = nullptr;  // null unless asked for
  Vec2* uvs = nullptr;
  glm::vec4* tangents = nullptr;
  glm::vec4* colors = nullptr;
  uint32_t* indices = nullptr;
  size_t vertices = 0, triangles = 0;
};

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // --- building ---
  uint32_t addMaterial(Material material);
  // World-space triangles; normals and uvs may be empty (flat shading, uv = 0).
  // tangents (xyz, w = the bitangent's sign: glTF TANGENT) matter only to a material with a
  // normal map; without them they are generated from the uvs (below).
  void addMesh(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
               const std::vector<Vec2>& uvs, const std::vector<uint32_t>& indices, uint32_t material,
               const std::vector<glm::vec4>& tangents = {});

  // Instancing: a mesh that several nodes place is stored once, in its own space (a prototype,
  // its own Embree scene), and placed by instances (Embree instances carrying the transform).
  // Prototype 0 is the world itself: meshes placed once are stored there, in world space.
  uint32_t addPrototype();
  // Places prototype p (≥ 1) with objectToWorld; a mirroring transform (negative determinant)
  // keeps the object's counter-clockwise faces as front faces, as the glTF loader's world-space
  // meshes do.
  void addInstance(uint32_t prototype, const Mat4& objectToWorld);
  // Room for the meshes still to come in a prototype, so that appendMesh never moves what is
  // stored (the loader knows every count before it reads anything).
  void reserve(uint32_t prototype, size_t vertices, size_t triangles, const MeshAttributes& extra);
  // Room for one mesh in `prototype` (0: the world, in world space): the caller writes its
  // positions, attributes and indices (counter-clockwise triangles, 0-based within the mesh)
  // through the slot, then calls finishMesh() before appending anything else.
  MeshSlot appendMesh(uint32_t prototype, size_t vertices, size_t triangles, uint32_t material,
                      const MeshAttributes& attributes);
  // Checks the indices, normalises the normals, generates missing tangents of a normal-mapped
  // mesh, extends the bounds.
  void finishMesh();

  // At most one environment (EnvironmentLight) among them.
  void addLight(std::unique_ptr<Light> light);
  void setCamera(const Camera& camera) {
    camera_ = camera;
    cameraTanHalf_ = std::tan(0.5f * camera.yfov);
    hasCamera_ = true;
  }
  float cameraTanHalf() const { return cameraTanHalf_; }  // tan(yfov/2), for Camera's tanHalf overloads
  // The camera's ray through film position (x, y) in pixels (Camera::generateRay).
  Ray cameraRay(float x, float y, int width, int height) const {
    return camera_.generateRay(x, y, width, height, cameraTanHalf_);
  }
  // A camera the file places (a node with a perspective camera), named as `info` lists it.
  struct FileCamera {
    std::string name;  // "nodes[3] 'Front', cameras[1]"
    Camera camera;
  };
  void addFileCamera(FileCamera camera) { fileCameras_.push_back(std::move(camera)); }
  // The acceleration structure: Embree's fast BVH, or its compact one (about half the memory,
  // rays ~10% slower); Auto takes the compact one from kCompactTriangles stored triangles on.
  enum class BvhLayout { Auto, Fast, Compact };
  static constexpr size_t kCompactTriangles = size_t(1) << 20;
  void setBvhLayout(BvhLayout layout) { bvhLayout_ = layout; }
  // Builds the BVH, one AreaLight per emissive triangle and the light-selection distribution.
  void commit();

  // --- queries ---
  bool intersect(const Ray& ray, SurfaceHit* hit) const;
  bool occluded(const Ray& ray) const;
  // intersect() for up to kPacket rays at once (lane k where active[k]), through Embree's
  // packets (rtcIntersect8): each lane's found[k] and hits[k] are bit for bit what the one-ray
  // query returns for it. `coherent` tells Embree the rays start together and run nearly
  // parallel (one pixel row's camera rays), which it traverses as a bundle. A packet of one
  // active lane takes the one-ray query.
  static constexpr int kPacket = 8;
  void intersect(const Ray* rays, const bool* active, bool coherent, SurfaceHit* hits, bool* found) const;
  // Ray leaving the surface at `hit` in direction d, offset off the surface to avoid self-hits.
  Ray spawnRay(const SurfaceHit& hit, const Vec3& d) const;
  // Beer–Lambert along the segment a ray travelled (direction d, unit) to reach `hit`: when it
  // ran inside an absorbing volume, which it did if it met the back face of that volume's
  // surface, exp(−σ t) = attenuationColor^(t / attenuationDistance) at the path's wavelengths;
  // 1 otherwise. Every estimator multiplies its path throughput by it after each intersection.
  // Volumes are assumed not nested, and a segment that starts inside one and ends on another
  // surface inside it (a light inside glass) is not attenuated.
  Spectrum transmittance(const SurfaceHit& hit, const Vec3& d, const SampledWavelengths& lambda) const {
    if (!absorbing_ || !hit.material->absorbs() || !(glm::dot(d, hit.ng) > 0)) return Spectrum(1.0f);
    const Spectrum c = hit.material->attenuationColor.eval(Vec2(0.0f), lambda);
    const float exponent = hit.t / hit.material->attenuationDistance;
    return Spectrum(std::pow(c[0], exponent), std::pow(c[1], exponent), std::pow(c[2], exponent));
  }
  bool hasAbsorbingVolumes() const { return absorbing_; }
  // Shadow ray from hit towards a light sample at `distance` along wi: is it unblocked?
  bool visible(const SurfaceHit& hit, const Vec3& wi, float distance) const;
  // Triangles are numbered over the whole scene: the world's in the order they were added, then
  // each instance's copy of its prototype's. triangleCount() counts them all (an instanced mesh
  // once per placement); storedTriangleCount() counts what is stored.
  // The surface at barycentric (b1, b2) of triangle `primitive`, as intersect() reports a hit
  // there (t left at infinity). For methods that mesh the surfaces themselves (radiosity).
  SurfaceHit surfaceAt(uint32_t primitive, float b1, float b2) const;
  // A triangle's corners (world space) and material index.
  std::array<Vec3, 3> trianglePositions(uint32_t primitive) const;
  uint32_t triangleMaterial(uint32_t primitive) const;
  // A triangle's vertex normals in trianglePositions' corner order (world space, as stored: the
  // hit's shading normal is their interpolation, normalised); false if its mesh has none.
  bool triangleNormals(uint32_t primitive, std::array<Vec3, 3>* normals) const;
  // The area light a triangle is (null if none): an emissive material's triangle, unless its
  // emissive texture is black over it.
  const AreaLight* triangleLight(uint32_t primitive) const;

  const Camera& camera() const { return camera_; }
  bool hasCamera() const { return hasCamera_; }
  // Every camera the file places, in scene order (`--camera N` picks the N-th), and which one
  // renders ("automatic" where the file has none).
  const std::vector<FileCamera>& fileCameras() const { return fileCameras_; }
  std::string cameraSource;
  // The units the file's light values were read in, and why ("radiometric (asset.extras...)").
  std::string units;
  // Where the environment comes from and what it is ("--env: constant 1, 1, 1 W/(m2 sr)"), or empty.
  std::string environmentSource;
  const std::vector<std::unique_ptr<Light>>& lights() const { return lights_; }
  // The sky rays that leave the scene see (null without one), and its index in lights().
  const EnvironmentLight* environment() const { return environment_; }
  int environmentIndex() const { return environmentIndex_; }
  // Lights are chosen in proportion to their power (average over RGB).
  const AliasTable& lightDistribution() const { return lightDistribution_; }
  Spectrum totalPower() const;
  const std::vector<Material>& materials() const { return materials_; }
  size_t triangleCount() const { return triangleCount_; }
  size_t storedTriangleCount() const;
  size_t instanceCount() const { return instances_.size() - 1; }
  bool compactBvh() const { return compact_; }
  // The compact layout's stored triangles that make quads in pairs (the rest are quads alone).
  size_t pairedTriangleCount() const;
  const Bounds& bounds() const { return bounds_; }
  float epsilon() const { return epsilon_; }
  RTCScene embreeScene() const { return rtcScene_; }
  // For code that queries embreeScene() itself: each Embree geometry's first triangle number, so
  // that a hit is triangle first[geomID] + primID, Embree's (u, v) the barycentrics (b1, b2) of
  // trianglePositions' corners. Empty where that does not hold (instances, the compact layout).
  std::vector<uint32_t> geometryFirstTriangles() const;
  // Whether any mesh has vertex colours (COLOR_0).
  bool hasVertexColors() const;
  // Rays (closest-hit and shadow) traced so far by this process, for benchmarks: complete after
  // a parallel loop returns (core/ray_counts.h).
  static uint64_t raysTraced();
  static uint64_t shadowRaysTraced();  // the occluded() queries among them
  // Adds rays that code with its own Embree queries traced (integrators/path_lanes.cpp).
  static void countRays(uint64_t closest, uint64_t shadow);
  std::string source;  // file it was loaded from, for messages and metadata

 private:
  // One mesh (a glTF primitive): one Embree geometry, one material. Its vertices and triangles
  // are a range of its prototype's arrays, its indices 0-based within its vertices; each
  // attribute it has, a range of that attribute's array (−1: it has none).
  struct Part {
    uint32_t firstVertex, vertexCount, firstTriangle, triangleCount, material;
    int64_t firstNormal = -1, firstUV = -1, firstTangent = -1, firstColor = -1;
    // Compact layout only (Prototype::paired): its quads start at firstQuad in the prototype's
    // quads; the first `pairs` are pairs of its triangles, the rest single triangles.
    uint32_t firstQuad = 0, pairs = 0;
  };
  struct Prototype {
    std::vector<Vec3> positions;  // world space for prototype 0, the object's space otherwise
    std::vector<Vec3> normals;
    std::vector<Vec2> uvs;
    std::vector<glm::vec4> tangents;
    std::vector<glm::vec4> colors;
    std::vector<uint32_t> indices;  // 3 per triangle, into its part's vertices
    // The compact layout stores the triangles as Embree quads instead, 4 indices a quad, and
    // `indices` is freed (pairIntoQuads): a part's triangles 2k and 2k + 1 are the halves
    // (v0, v1, v3) and (v2, v3, v1) of its quad k < pairs; each later triangle is a quad
    // (a, b, c, c). Half the primitives: the BVH takes about half the memory.
    std::vector<uint32_t> quads;
    bool paired = false;
    std::vector<Vec3> faceNormals;  // per triangle, unit (faceNormal); empty in the compact layout
    std::vector<Part> parts;
    Bounds bounds;
    RTCScene rtc = nullptr;  // instanced prototypes' own Embree scene
    uint32_t triangles = 0;
    uint32_t triangleCount() const { return triangles; }
  };
  // A placement of a prototype. Instance 0 places prototype 0 (the world) as it is.
  struct Instance {
    uint32_t prototype = 0;
    Mat4 toWorld{1.0f};
    glm::mat3 linear{1.0f}, normalMatrix{1.0f};  // the transform's linear part, its inverse transpose
    bool mirrors = false;                         // negative determinant
    uint32_t firstPrimitive = 0;                  // its triangles' numbers start here
    // Per part of the prototype: per triangle, the index of its AreaLight in lights_ or −1;
    // empty for a part that is not emissive.
    std::vector<std::vector<int32_t>> lights;
  };
  // Geometry user data for the alpha filter: which part of which prototype.
  struct FilterData {
    const Scene* scene;
    uint32_t prototype, part;
  };
  // Embree filter for triangles whose material is MASK or BLEND: rejects a hit where the
  // surface is absent (alpha below the cutoff; for BLEND, a hash of the ray and the hit point
  // at or above alpha), so traversal goes on past it, for closest hits and shadow rays alike.
  static void alphaFilter(const RTCFilterFunctionNArguments* args);
  bool presentAt(const Prototype& proto, const Part& part, uint32_t primID, float b1, float b2, uint64_t rayHash) const;
  // Triangle primID of the part: its corners, indices into the part's vertices.
  static std::array<uint32_t, 3> corners(const Prototype& proto, const Part& part, uint32_t primID);
  // What Embree reports on a part (its primitive primID, hit coordinates u, v) as the triangle
  // primID and its barycentrics (b1, b2): the same numbers unless the prototype is paired.
  static void triangleOfHit(const Prototype& proto, const Part& part, uint32_t* primID, float* b1, float* b2);
  // The compact layout's storage: each part's triangles paired across shared edges into quads.
  static void pairIntoQuads(Prototype& proto);
  // Triangle (a, b, c)'s unit normal, on the side from which the corners run counter-clockwise.
  static Vec3 faceNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    return len > 0 ? n / len : Vec3(0, 0, 1);
  }
  // The hit Embree reported (its instance, geometry, primitive, u, v and distance t) as a surface.
  void hitOf(unsigned instID, unsigned geomID, uint32_t primID, float u, float v, float t, SurfaceHit* hit) const;
  // The surface on triangle primID of the part, placed by the instance.
  void surfaceOf(const Instance& inst, uint32_t part, uint32_t primID, float b1, float b2, SurfaceHit* hit) const;
  // Triangle `primitive`'s instance, part and triangle within the part.
  void locate(uint32_t primitive, uint32_t* instance, uint32_t* part, uint32_t* primID) const;
  RTCScene buildEmbreeScene(uint32_t prototype, RTCScene into);
  void createAreaLights(Instance& inst);

  RTCDevice device_ = nullptr;
  RTCScene rtcScene_ = nullptr;
  std::vector<Prototype> prototypes_;
  std::vector<Instance> instances_;
  // Top-level Embree geometry IDs: the world's parts first (ID = part index), then one instance
  // geometry per instance 1, 2, …: instance = ID − (world parts) + 1.
  std::deque<FilterData> filterData_;  // stable addresses for Embree's user pointers
  std::vector<Material> materials_;
  std::vector<std::unique_ptr<Light>> lights_;
  AliasTable lightDistribution_;
  const EnvironmentLight* environment_ = nullptr;
  int environmentIndex_ = -1;
  Camera camera_;
  float cameraTanHalf_ = std::tan(0.5f * Camera().yfov);  // tan(yfov/2) of camera_
  std::vector<FileCamera> fileCameras_;
  bool hasCamera_ = false, committed_ = false, meshOpen_ = false;
  uint32_t lastPrototype_ = 0;  // of the open mesh
  BvhLayout bvhLayout_ = BvhLayout::Auto;
  bool absorbing_ = false;  // some material absorbs (Material::absorbs)
  bool compact_ = false;
  size_t triangleCount_ = 0;
  Bounds bounds_;
  float epsilon_ = 1e-4f;
};

}  // namespace pl
