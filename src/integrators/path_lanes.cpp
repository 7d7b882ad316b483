// The path tracer (integrators/path.cpp) in 16 SIMD lanes. Read path.cpp first: this file and
// its kernel (path_lanes_kernel.h, compiled once per instruction set) compute the same
// estimator, step for step, for 16 paths per instruction.
//
// A bounce of 16 paths: their rays go to the scene's Embree scene as one packet
// (rtcIntersect16); the hits are rebuilt from the triangles' records (position and shading
// normal interpolated as Scene::surfaceOf does); emission found by BSDF sampling is weighted
// against next-event estimation; Lambertian lanes pick a light, sample a point on it and send
// their shadow rays as one packet (rtcOccluded16); every lane samples its BSDF (the Lambertian's
// cosine lobe, and where any lane needs them the mirror and the glass's Fresnel choice, each lane
// keeping its own); Russian roulette from the fourth bounce. Then the finished paths are
// squeezed out (stream compaction), so that the next bounce's packets are full again.
//
// Each path keeps its sampler's stream (Rng::state, increment) and draws from it in the order
// PathIntegrator::Li does, including where a draw is skipped. The results differ from Li's only
// by rounding (1/√ multiplied where Li divides, the shading frame's round trip skipped), which
// can flip a rare comparison (a roulette draw next to q, a cosine next to 0).
//
// Why lanes: the arithmetic of 16 paths runs in the time of about one, and Embree's packets
// cost less per ray than single rays; with the work of a few rows (1024 paths) the packets
// stay full. Measured: docs/pages/explanation/performance.md.
#include "integrators/path_lanes.h"

#include <cstddef>
#include <cstring>
#include <unordered_map>

#include "bsdfs/dielectric.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/mirror.h"
#include "core/lanes_isa.h"
#include "lights/area_light.h"

namespace pl {

// The lanes read a triangle's record as one 16-word vector (lanes::gatherRecords): words 0–11
// the corners and ng, 12–14 the indices.
static_assert(sizeof(PathLanes::Triangle) == 64 && offsetof(PathLanes::Triangle, ng) == 36 &&
              offsetof(PathLanes::Triangle, normals) == 48 && offsetof(PathLanes::Triangle, light) == 56);

std::string PathLanes::unsupported(const Scene& scene) {
  if (!lanes::lanesPay()) return "a CPU without AVX-512, where lanes are slower than one path at a time";
  if (scene.environment()) return "an environment light";
  if (scene.hasAbsorbingVolumes()) return "an absorbing volume";
  if (scene.lights().empty() || scene.lightDistribution().total() <= 0) return "no light";
  if (scene.geometryFirstTriangles().empty()) return "instances or the compact BVH";
  if (scene.hasVertexColors()) return "vertex colours";
  for (const auto& light : scene.lights()) {
    if (light->type() != LightType::kArea) return std::string("a ") + light->name() + " light";
    if (static_cast<const AreaLight&>(*light).textured()) return "a textured area light";
  }
  std::vector<bool> used(scene.materials().size(), false);
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) used[scene.triangleMaterial(t)] = true;
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials()[i];
    const std::string name = "material '" + m.name + "'";
    if (!m.bsdf) return name + " has no BSDF";
    if (m.normalMap || m.alpha || m.alphaMode != AlphaMode::Opaque) return name + " has a normal map or alpha";
    switch (m.bsdf->bsdfClass()) {
      case BSDFClass::kLambertian:
        if (!static_cast<const Lambertian&>(*m.bsdf).albedo().isConstant()) return name + " is textured";
        break;
      case BSDFClass::kMirror:
        if (!static_cast<const Mirror&>(*m.bsdf).reflectance().isConstant()) return name + " is textured";
        break;
      case BSDFClass::kDielectric:
        if (static_cast<const Dielectric&>(*m.bsdf).abbe() > 0) return name + " disperses";
        break;
      case BSDFClass::kOther:
        return name + " is a " + m.bsdf->name() + " BSDF";
    }
  }
  return {};
}

PathLanes::PathLanes(const Scene& scene) : scene_(scene), isa_(lanes::bestIsa()) {
  if (const std::string why = unsupported(scene); !why.empty()) throw Error("path lanes: " + why);
  for (const Material& m : scene.materials()) {
    int32_t kind = kLambertian;
    Vec3 color(0.0f);
    float eta = 1.0f;
    const BSDFClass bsdfClass = m.bsdf ? m.bsdf->bsdfClass() : BSDFClass::kOther;
    if (bsdfClass == BSDFClass::kLambertian) {
      color = static_cast<const Lambertian&>(*m.bsdf).albedo().factor();
    } else if (bsdfClass == BSDFClass::kMirror) {
      kind = kMirror, color = static_cast<const Mirror&>(*m.bsdf).reflectance().factor();
    } else if (bsdfClass == BSDFClass::kDielectric) {
      kind = kGlass, eta = static_cast<const Dielectric&>(*m.bsdf).eta();
    }
    surfaces_.push_back({kind, color, eta});
  }
  std::unordered_map<const Light*, int> lightIndex;
  const AliasTable& pick = scene.lightDistribution();
  for (size_t i = 0; i < scene.lights().size(); ++i) {
    const auto& area = static_cast<const AreaLight&>(*scene.lights()[i]);
    lightIndex[&area] = int(i);
    emitters_.push_back({area.corner(0), area.corner(1), area.corner(2), area.normal(), area.meanRadiance(), area.area(),
                       pick.pmf(i), area.twoSided() ? 1 : 0});
  }
  const uint32_t count = uint32_t(scene.triangleCount());
  triangles_.resize(count);
  for (uint32_t t = 0; t < count; ++t) {
    Triangle& tri = triangles_[t];
    const auto p = scene.trianglePositions(t);
    tri.p0 = p[0], tri.p1 = p[1], tri.p2 = p[2];
    tri.ng = scene.surfaceAt(t, 1.0f / 3, 1.0f / 3).ng;
    std::array<Vec3, 3> n;
    tri.normals = -1;
    if (scene.triangleNormals(t, &n)) {
      tri.normals = int32_t(normals_.size());
      normals_.push_back({n[0], n[1], n[2]});
    }
    tri.material = int32_t(scene.triangleMaterial(t));
    const AreaLight* light = scene.triangleLight(t);
    tri.light = light ? lightIndex.at(light) : -1;
  }
  // The scene's own Embree scene answers the lanes' rays: the same hits as Scene::intersect.
  firstTriangle_ = scene.geometryFirstTriangles();
}

// What every copy of the kernel reads.
namespace {
struct Context {
  const std::vector<PathLanes::Triangle>& triangles;
  const std::vector<uint32_t>& firstTriangle;  // by Embree geometry
  const std::vector<PathLanes::Normals>& normals;
  const std::vector<PathLanes::Surface>& surfaces;
  const std::vector<PathLanes::Emitter>& emitters;
  const AliasTable& lightPick;
  RTCScene rtc;
  float eps;
  int maxDepth;
};
}  // namespace

}  // namespace pl

// The kernel (path_lanes_kernel.h), compiled for each instruction set: core/lanes.h says why.
#define PL_LANES_KERNEL "integrators/path_lanes_kernel.h"
#include "core/lanes_copies.h"
#undef PL_LANES_KERNEL

namespace pl {

void PathLanes::trace(PixelIntegrator::CameraSample* samples, int n, int maxDepth) const {
  const Context c{triangles_, firstTriangle_, normals_, surfaces_, emitters_, scene_.lightDistribution(), scene_.embreeScene(),
                  scene_.epsilon(), maxDepth};
  switch (isa_) {
    case lanes::Isa::Avx512: return path_lanes::avx512::traceLanes(samples, n, c);
    case lanes::Isa::Baseline: return path_lanes::baseline::traceLanes(samples, n, c);
  }
}

}  // namespace pl
