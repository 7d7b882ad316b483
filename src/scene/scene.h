// A scene: triangles in world space on one Embree BVH, their materials, the lights and the
// camera. Built through the add*() calls (by the glTF loader or by tests), then commit().
#pragma once
#include <embree3/rtcore.h>

#include <array>
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
  std::shared_ptr<const AlphaTexture> alpha = nullptr;  // set unless alphaMode is Opaque
  std::shared_ptr<const NormalMap> normalMap = nullptr;  // glTF normalTexture, or null
};

struct SurfaceHit {
  float t = INFINITY;
  Vec3 p;
  Vec3 ng;       // geometric normal, unit, on the front (counter-clockwise) side
  Frame shading; // shading normal frame (interpolated NORMAL, or ng when the mesh has none)
  Vec2 uv;
  Vec2 barycentric{0.0f};  // (b1, b2): p = (1 − b1 − b2) v0 + b1 v1 + b2 v2 on the triangle
  uint32_t primitive = 0;
  const BSDF* bsdf = nullptr;
  const AreaLight* light = nullptr;  // non-null on emissive triangles
  int lightIndex = -1;
  // The shading normal is not the geometric one (interpolated NORMAL, a normal map): estimators
  // that mix the two (photon density estimation, light paths) then need their corrections.
  bool shadingDiffers() const { return shading.n != ng; }
};

struct Bounds {
  Vec3 lo{INFINITY}, hi{-INFINITY};
  void extend(const Vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  bool empty() const { return lo.x > hi.x; }
  Vec3 center() const { return 0.5f * (lo + hi); }
  float radius() const { return 0.5f * glm::length(hi - lo); }
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
  // At most one environment (EnvironmentLight) among them.
  void addLight(std::unique_ptr<Light> light);
  void setCamera(const Camera& camera) { camera_ = camera; hasCamera_ = true; }
  // A camera the file places (a node with a perspective camera), named as `info` lists it.
  struct FileCamera {
    std::string name;  // "nodes[3] 'Front', cameras[1]"
    Camera camera;
  };
  void addFileCamera(FileCamera camera) { fileCameras_.push_back(std::move(camera)); }
  // Builds the BVH, one AreaLight per emissive triangle and the light-selection distribution.
  void commit();

  // --- queries ---
  bool intersect(const Ray& ray, SurfaceHit* hit) const;
  bool occluded(const Ray& ray) const;
  // Ray leaving the surface at `hit` in direction d, offset off the surface to avoid self-hits.
  Ray spawnRay(const SurfaceHit& hit, const Vec3& d) const;
  // Shadow ray from hit towards a light sample at `distance` along wi: is it unblocked?
  bool visible(const SurfaceHit& hit, const Vec3& wi, float distance) const;
  // The surface at barycentric (b1, b2) of triangle `primitive`, as intersect() reports a hit
  // there (t left at infinity). For methods that mesh the surfaces themselves (radiosity).
  SurfaceHit surfaceAt(uint32_t primitive, float b1, float b2) const;
  // A triangle's corners (world space) and material index.
  std::array<Vec3, 3> trianglePositions(uint32_t primitive) const;
  uint32_t triangleMaterial(uint32_t primitive) const { return triangles_[primitive].material; }
  // The area light a triangle is (null if none): an emissive material's triangle, unless its
  // emissive texture is black over it.
  const AreaLight* triangleLight(uint32_t primitive) const {
    const int32_t l = triangles_[primitive].light;
    return l >= 0 ? static_cast<const AreaLight*>(lights_[size_t(l)].get()) : nullptr;
  }

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
  size_t triangleCount() const { return triangles_.size(); }
  const Bounds& bounds() const { return bounds_; }
  float epsilon() const { return epsilon_; }
  RTCScene embreeScene() const { return rtcScene_; }
  // Rays (closest-hit and shadow) traced so far by this process, for benchmarks. Counted per
  // thread without atomics; a thread adds its count to the total when it exits.
  static uint64_t raysTraced();
  std::string source;  // file it was loaded from, for messages and metadata

 private:
  struct Triangle {
    uint32_t v[3];
    uint32_t material;
    int32_t light = -1;
    bool smooth = false;  // the mesh has NORMALs
    bool hasUV = false;   // the mesh has TEXCOORD_0
    bool hasTangent = false;  // normal-mapped: tangents_ holds its vertices' tangents
  };
  // Embree filter for triangles whose material is MASK or BLEND: rejects a hit where the
  // surface is absent (alpha below the cutoff; for BLEND, a hash of the ray and the hit point
  // at or above alpha), so traversal goes on past it, for closest hits and shadow rays alike.
  static void alphaFilter(const RTCFilterFunctionNArguments* args);
  bool presentAt(uint32_t triangle, float b1, float b2, uint64_t rayHash) const;
  uint32_t triangleOf(unsigned geomID, unsigned primID) const {
    const auto& map = geometryTriangles_[geomID];
    return map.empty() ? primID : map[primID];
  }
  RTCDevice device_ = nullptr;
  RTCScene rtcScene_ = nullptr;
  // Per Embree geometry (opaque triangles first, then the alpha-tested ones), its primitives'
  // triangle indices; empty when it holds every triangle in order.
  std::vector<std::vector<uint32_t>> geometryTriangles_;
  std::vector<Vec3> positions_, normals_;
  std::vector<Vec2> uvs_;
  std::vector<glm::vec4> tangents_;  // per vertex; only normal-mapped meshes' are meaningful
  std::vector<Vec3> faceNormals_;
  std::vector<Triangle> triangles_;
  std::vector<Material> materials_;
  std::vector<std::unique_ptr<Light>> lights_;
  AliasTable lightDistribution_;
  const EnvironmentLight* environment_ = nullptr;
  int environmentIndex_ = -1;
  Camera camera_;
  std::vector<FileCamera> fileCameras_;
  bool hasCamera_ = false, committed_ = false;
  Bounds bounds_;
  float epsilon_ = 1e-4f;
};

}  // namespace pl
