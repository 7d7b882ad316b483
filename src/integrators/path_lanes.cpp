// The path tracer (integrators/path.cpp) in 16 SIMD lanes. Read path.cpp first: this file
// computes the same estimator, step for step, for 16 paths per instruction.
//
// A bounce of 16 paths: their rays go to Embree as one packet (rtcIntersect16); the hits are
// rebuilt from the triangles' records (position and shading normal interpolated as
// Scene::surfaceOf does); emission found by BSDF sampling is weighted against next-event
// estimation; Lambertian lanes pick a light, sample a point on it and send their shadow rays as
// one packet (rtcOccluded16); every lane samples its BSDF (the Lambertian's cosine lobe, the
// mirror, the glass's Fresnel choice: all three computed, each lane keeping its own); Russian
// roulette from the fourth bounce. Then the finished paths are squeezed out (stream compaction),
// so that the next bounce's packets are full again.
//
// Each path keeps its sampler's stream (Rng::state, increment) and draws from it in the order
// PathIntegrator::Li does, including where a draw is skipped. The results differ from Li's only
// by rounding (1/√ multiplied where Li divides, the shading frame's round trip skipped), which
// can flip a rare comparison (a roulette draw next to q, a cosine next to 0).
//
// Why lanes: the arithmetic of 16 paths runs in the time of about one, and Embree's packets
// cost less per ray than single rays; with the work of a row (hundreds of paths) the packets
// stay full. Measured: docs/performance.md.
#include "integrators/path_lanes.h"

#include <cstring>
#include <unordered_map>

#include "bsdfs/dielectric.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/mirror.h"
#include "core/lanes.h"
#include "lights/area_light.h"

namespace pl {

std::string PathLanes::unsupported(const Scene& scene) {
  if (scene.environment()) return "an environment light";
  if (scene.hasAbsorbingVolumes()) return "an absorbing volume";
  if (scene.lights().empty() || scene.lightDistribution().total() <= 0) return "no light";
  for (const auto& light : scene.lights()) {
    if (std::string(light->name()) != "area") return std::string("a ") + light->name() + " light";
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
    if (const auto* lambertian = dynamic_cast<const Lambertian*>(m.bsdf.get())) {
      if (!lambertian->albedo().isConstant()) return name + " is textured";
    } else if (const auto* mirror = dynamic_cast<const Mirror*>(m.bsdf.get())) {
      if (!mirror->reflectance().isConstant()) return name + " is textured";
    } else if (const auto* glass = dynamic_cast<const Dielectric*>(m.bsdf.get())) {
      if (glass->abbe() > 0) return name + " disperses";
    } else {
      return name + " is a " + m.bsdf->name() + " BSDF";
    }
  }
  // Vertex colours tint every BSDF's colour: checked at each triangle's corners.
  const Vec2 at[3] = {{0, 0}, {1, 0}, {0, 1}};
  for (uint32_t t = 0; t < scene.triangleCount(); ++t)
    for (const Vec2& b : at)
      if (scene.surfaceAt(t, b.x, b.y).color != Spectrum(1.0f)) return "triangle " + std::to_string(t) + " has a vertex colour";
  return {};
}

PathLanes::PathLanes(const Scene& scene) : scene_(scene) {
  if (const std::string why = unsupported(scene); !why.empty()) throw Error("path lanes: " + why);
  for (const Material& m : scene.materials()) {
    int32_t kind = kLambertian;
    Vec3 color(0.0f);
    float eta = 1.0f;
    if (const auto* lambertian = dynamic_cast<const Lambertian*>(m.bsdf.get())) {
      color = lambertian->albedo().factor();
    } else if (const auto* mirror = dynamic_cast<const Mirror*>(m.bsdf.get())) {
      kind = kMirror, color = mirror->reflectance().factor();
    } else if (const auto* glass = dynamic_cast<const Dielectric*>(m.bsdf.get())) {
      kind = kGlass, eta = glass->eta();
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
      normals_.insert(normals_.end(), n.begin(), n.end());
    }
    tri.material = int32_t(scene.triangleMaterial(t));
    const AreaLight* light = scene.triangleLight(t);
    tri.light = light ? lightIndex.at(light) : -1;
  }
  // An Embree scene of the world-space triangles in one geometry, so that primID is the index.
  device_ = rtcNewDevice(nullptr);
  rtc_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtc_, RTC_BUILD_QUALITY_HIGH);  // as Scene builds its own
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * size_t(count)));
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, count));
  for (uint32_t t = 0; t < count; ++t) {
    const Vec3* p[3] = {&triangles_[t].p0, &triangles_[t].p1, &triangles_[t].p2};
    for (int k = 0; k < 3; ++k) {
      std::memcpy(vertices + 9 * size_t(t) + 3 * k, p[k], sizeof(Vec3));
      indices[3 * size_t(t) + k] = 3 * t + uint32_t(k);
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(rtc_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(rtc_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw Error("path lanes: Embree could not build the scene");
}

PathLanes::~PathLanes() {
  rtcReleaseScene(rtc_);
  rtcReleaseDevice(device_);
}

namespace {

using namespace lanes;

// 16 paths' state, one array per quantity.
struct alignas(64) Paths {
  float ox[kLanes], oy[kLanes], oz[kLanes], tmin[kLanes], tmax[kLanes];  // the next ray
  float dx[kLanes], dy[kLanes], dz[kLanes];
  float Lr[kLanes], Lg[kLanes], Lb[kLanes];  // radiance so far
  float br[kLanes], bg[kLanes], bb[kLanes];  // throughput β = ∏ f·cos/pdf
  float bsdfPdf[kLanes], etaScale[kLanes];   // the last direction's density; ∏ η² (roulette)
  float px[kLanes], py[kLanes], pz[kLanes];  // the previous vertex (emission's MIS density)
  uint64_t state[kLanes], increment[kLanes]; // the sampler's stream
  int32_t depth[kLanes], sample[kLanes], specular[kLanes], alive[kLanes];
};

struct Vec3s {  // a 3-vector in 16 lanes
  Floats x, y, z;
};
PL_HOT_INLINE Floats dot(const Vec3s& a, const Vec3s& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
PL_HOT_INLINE Vec3s operator*(Floats s, const Vec3s& v) { return {s * v.x, s * v.y, s * v.z}; }
PL_HOT_INLINE Vec3s operator+(const Vec3s& a, const Vec3s& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
PL_HOT_INLINE Vec3s operator-(const Vec3s& a, const Vec3s& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
PL_HOT_INLINE Vec3s operator-(const Vec3s& a) { return {-a.x, -a.y, -a.z}; }
PL_HOT_INLINE Vec3s select(Ints m, const Vec3s& a, const Vec3s& b) {
  return {m != 0 ? a.x : b.x, m != 0 ? a.y : b.y, m != 0 ? a.z : b.z};
}
PL_HOT_INLINE Vec3s load3(const float* x, const float* y, const float* z) { return {load(x), load(y), load(z)}; }
PL_HOT_INLINE void store3(float* x, float* y, float* z, const Vec3s& v) { store(x, v.x), store(y, v.y), store(z, v.z); }

// Gathers one Vec3 field of a record per lane.
struct Gather3 {
  alignas(64) float x[kLanes], y[kLanes], z[kLanes];
  PL_HOT_INLINE void set(int k, const Vec3& v) { x[k] = v.x, y[k] = v.y, z[k] = v.z; }
  PL_HOT_INLINE Vec3s get() const { return load3(x, y, z); }
};

PL_HOT_INLINE Floats powerHeuristic(Floats pdfA, Floats pdfB) {
  const Floats a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0 ? a / (a + b) : Floats{};
}

// fresnelDielectric (optics/optics.h) lane by lane: cosθ_i < 0 arrives from inside (η inverted).
PL_HOT_INLINE Floats fresnelDielectric(Floats cosThetaI, Floats eta) {
  const Ints inside = cosThetaI < 0;
  eta = inside ? 1.0f / eta : eta;
  cosThetaI = abs(cosThetaI);
  const Floats sin2ThetaT = (1.0f - cosThetaI * cosThetaI) / (eta * eta);
  const Floats cosThetaT = sqrt(max(Floats{}, 1.0f - sin2ThetaT));
  const Floats rs = (cosThetaI - eta * cosThetaT) / (cosThetaI + eta * cosThetaT);
  const Floats rp = (eta * cosThetaI - cosThetaT) / (eta * cosThetaI + cosThetaT);
  return sin2ThetaT >= 1.0f ? splat(1.0f) : 0.5f * (rs * rs + rp * rp);
}

// Embree rejects rays with a NaN or huge component; Scene::intersect treats them as misses.
PL_HOT_INLINE Ints embreeValid(const Vec3s& o, const Vec3s& d) {
  const Floats sum = abs(o.x) + abs(o.y) + abs(o.z) + abs(d.x) + abs(d.y) + abs(d.z);
  return sum <= 1.844e18f;
}

struct Counts {
  uint64_t rays = 0, shadowRays = 0;
};

struct Context {
  const std::vector<PathLanes::Triangle>& triangles;
  const std::vector<Vec3>& normals;
  const std::vector<PathLanes::Surface>& surfaces;
  const std::vector<PathLanes::Emitter>& emitters;
  const AliasTable& lightPick;
  RTCScene rtc;
  float eps;
  int maxDepth;
};

// The closest hits of the rays of P's live lanes, into rh; `valid` marks the lanes traced.
PL_HOT_INLINE void intersect(const Paths& P, const Context& c, RTCIntersectContext* rtcContext, RTCRayHit16* rh, int32_t* valid,
                             Counts* counts) {
  const Vec3s o = load3(P.ox, P.oy, P.oz), d = load3(P.dx, P.dy, P.dz);
  store(valid, load(P.alive) & embreeValid(o, d));
  store(rh->ray.org_x, o.x), store(rh->ray.org_y, o.y), store(rh->ray.org_z, o.z);
  store(rh->ray.dir_x, d.x), store(rh->ray.dir_y, d.y), store(rh->ray.dir_z, d.z);
  store(rh->ray.tnear, load(P.tmin)), store(rh->ray.tfar, load(P.tmax)), store(rh->ray.time, Floats{});
  for (int k = 0; k < kLanes; ++k)
    rh->ray.mask[k] = 0xFFFFFFFFu, rh->ray.id[k] = 0, rh->ray.flags[k] = 0, rh->hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  int rays = 0;
  for (int k = 0; k < kLanes; ++k) rays += valid[k] != 0;
  if (rays > 0) rtcIntersect16(valid, c.rtc, rtcContext, rh);
  counts->rays += uint64_t(rays);
}

// Asks for the hit triangles' records ahead of their use (they are the bounce's cache misses).
PL_HOT_INLINE void prefetch(const RTCRayHit16& rh, const int32_t* valid, const Context& c) {
  for (int k = 0; k < kLanes; ++k)
    if (valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID) __builtin_prefetch(&c.triangles[rh.hit.primID[k]]);
}

// The rest of a bounce for P's live lanes, whose rays' hits are rh (`valid`: the lanes traced).
// The paths that end give their radiance to their camera samples; P.alive keeps the others.
PL_HOT_INLINE void shade(Paths& P, const RTCRayHit16& rh, const int32_t* valid, const Context& c, RTCIntersectContext* rtcContext,
                         PixelIntegrator::CameraSample* samples, Counts* counts) {
  const Vec3s d = load3(P.dx, P.dy, P.dz);
  // The hits' triangles, materials and emitters, gathered lane by lane (a miss reads record 0).
  Gather3 p0, p1, p2, n0, n1, n2, ng, color, lightN, lightLe;
  alignas(64) float eta[kLanes], lightArea[kLanes], lightPmf[kLanes];
  alignas(64) int32_t hit[kLanes], smooth[kLanes], kind[kLanes], emits[kLanes], twoSided[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    hit[k] = valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? -1 : 0;
    const PathLanes::Triangle& tri = c.triangles[hit[k] ? rh.hit.primID[k] : 0];
    p0.set(k, tri.p0), p1.set(k, tri.p1), p2.set(k, tri.p2), ng.set(k, tri.ng);
    smooth[k] = tri.normals >= 0 ? -1 : 0;
    const PathLanes::Surface& m = c.surfaces[size_t(tri.material)];
    kind[k] = m.kind, color.set(k, m.color), eta[k] = m.eta;
    const PathLanes::Emitter& light = c.emitters[tri.light >= 0 ? size_t(tri.light) : 0];
    emits[k] = tri.light >= 0 ? -1 : 0;
    lightN.set(k, light.n), lightLe.set(k, light.Le), lightArea[k] = light.area, lightPmf[k] = light.pmf;
    twoSided[k] = light.twoSided;
  }
  // The hit: p = b0 v0 + b1 v1 + b2 v2 with Embree's (u, v) = (b1, b2); the shading normal is
  // the vertex normals' interpolation, normalised (the geometric one without them).
  const Floats b1 = load(rh.hit.u), b2 = load(rh.hit.v), b0 = 1.0f - b1 - b2;
  const Vec3s p = b0 * p0.get() + b1 * p1.get() + b2 * p2.get();
  const Vec3s Ng = ng.get();
  const Ints isHit = load(hit), isSmooth = isHit & load(smooth);
  Vec3s ns = Ng;
  if (any(isSmooth)) {
    for (int k = 0; k < kLanes; ++k) {
      const PathLanes::Triangle& tri = c.triangles[hit[k] ? rh.hit.primID[k] : 0];
      if (tri.normals < 0) {  // a flat triangle among smooth ones: its lane keeps ng
        n0.set(k, tri.ng), n1.set(k, tri.ng), n2.set(k, tri.ng);
        continue;
      }
      const Vec3* n = &c.normals[size_t(tri.normals)];
      n0.set(k, n[0]), n1.set(k, n[1]), n2.set(k, n[2]);
    }
    const Vec3s n = b0 * n0.get() + b1 * n1.get() + b2 * n2.get();
    const Floats length = sqrt(dot(n, n));
    ns = select(isSmooth & (length > 0), (1.0f / length) * n, Ng);
  }

  Vec3s L = load3(P.Lr, P.Lg, P.Lb);
  Vec3s beta = load3(P.br, P.bg, P.bb);

  // Emission found by BSDF sampling (AreaLight::L: the front face, or both), weighted against
  // next-event estimation's density from the previous vertex, pmf · r² / (A |cos θ_light|).
  const Floats cosEmit = -dot(lightN.get(), d);
  const Ints lit = isHit & load(emits) & ((cosEmit > 0) | ((load(twoSided) != 0) & (cosEmit < 0)));
  if (any(lit)) {
    const Vec3s toHit = p - load3(P.px, P.py, P.pz);
    const Floats r2 = dot(toHit, toHit);
    const Floats cosLight = abs(dot(lightN.get(), toHit)) / sqrt(r2);
    const Floats pdfLi = (cosLight > 0) & (load(lightArea) > 0) ? r2 / (load(lightArea) * cosLight) : Floats{};
    const Floats w = load(P.specular) != 0 ? splat(1.0f) : powerHeuristic(load(P.bsdfPdf), load(lightPmf) * pdfLi);
    const Vec3s Le = lightLe.get();
    const Floats wLit = lit != 0 ? w : Floats{};
    L = L + wLit * Vec3s{beta.x * Le.x, beta.y * Le.y, beta.z * Le.z};
  }
  Ints go = isHit & (load(P.depth) < c.maxDepth);
  const Ints lambertian = load(kind) == PathLanes::kLambertian;
  const Vec3s albedo = color.get();

  // wo in the shading frame.
  Vec3s wo;
  const Frames shading(ns.x, ns.y, ns.z);
  shading.toLocal(-d.x, -d.y, -d.z, &wo.x, &wo.y, &wo.z);

  // Next-event estimation at Lambertian vertices (estimateDirect): a light by power, a point
  // uniform on it, f·Li·|cos θ|·w / p_light if the shadow ray is free.
  {
    const Ints nee = go & lambertian;
    const Floats uLight = uniforms(P.state, P.increment, nee);
    const Floats uy = uniforms(P.state, P.increment, nee), ux = uniforms(P.state, P.increment, nee);  // Sampler::get2D
    Gather3 q0, q1, q2, qn, qLe;
    alignas(64) float qArea[kLanes], qPmf[kLanes];
    alignas(64) int32_t qTwoSided[kLanes];
    for (int k = 0; k < kLanes; ++k) {
      float pmf = 0;
      const PathLanes::Emitter& light = c.emitters[nee[k] ? c.lightPick.sample(uLight[k], &pmf) : 0];
      q0.set(k, light.p0), q1.set(k, light.p1), q2.set(k, light.p2), qn.set(k, light.n), qLe.set(k, light.Le);
      qArea[k] = light.area, qPmf[k] = pmf, qTwoSided[k] = light.twoSided;
    }
    // AreaLight::sampleLi: Heitz's triangle map, y = bx p0 + by p1 + (1 − bx − by) p2.
    const Ints lower = ux < uy;
    const Floats bx = lower ? ux * 0.5f : ux - uy * 0.5f, by = lower ? uy - ux * 0.5f : uy * 0.5f;
    const Vec3s y = bx * q0.get() + by * q1.get() + (1.0f - bx - by) * q2.get();
    const Vec3s toLight = y - p;
    const Floats r2 = dot(toLight, toLight), distance = sqrt(r2);
    const Vec3s wi = (1.0f / distance) * toLight;
    const Floats cosLight = -dot(qn.get(), wi);
    const Ints emitting = (cosLight > 0) | ((load(qTwoSided) != 0) & (cosLight < 0));
    const Floats pdfLi = r2 / (load(qArea) * abs(cosLight));
    Vec3s wiLocal;
    shading.toLocal(wi.x, wi.y, wi.z, &wiLocal.x, &wiLocal.y, &wiLocal.z);
    // Lambertian::evaluate: both directions strictly on one side of the shading normal.
    const Floats side = wo.z < 0 ? splat(-1.0f) : splat(1.0f);
    const Ints sameSide = (side * wo.z > 0) & (side * wiLocal.z > 0);
    const Ints reflects = (albedo.x != 0) | (albedo.y != 0) | (albedo.z != 0);
    // sidesAgree: the geometric normal must agree that this is a reflection.
    const Ints agree = (dot(-d, Ng) * dot(wi, Ng) > 0) == (wo.z * wiLocal.z > 0);
    const Ints tried = nee & (r2 > 0) & (cosLight != 0) & emitting & sameSide & reflects & agree;
    // Scene::visible: from p offset along ±ng to one epsilon short of y.
    const Floats offset = dot(wi, Ng) > 0 ? splat(c.eps) : splat(-c.eps);
    const Vec3s origin = p + offset * Ng;
    const Vec3s target = p + distance * wi;
    const Vec3s toTarget = target - origin;
    const Floats length = sqrt(dot(toTarget, toTarget));
    const Ints nearby = length <= 2 * c.eps;  // visible without a ray
    alignas(64) int32_t shadowValid[kLanes];
    store(shadowValid, tried & ~nearby);
    alignas(64) RTCRay16 shadow;
    const Vec3s dir = (1.0f / length) * toTarget;
    store(shadow.org_x, origin.x), store(shadow.org_y, origin.y), store(shadow.org_z, origin.z);
    store(shadow.dir_x, dir.x), store(shadow.dir_y, dir.y), store(shadow.dir_z, dir.z);
    store(shadow.tnear, Floats{}), store(shadow.tfar, length - c.eps), store(shadow.time, Floats{});
    for (int k = 0; k < kLanes; ++k) shadow.mask[k] = 0xFFFFFFFFu, shadow.id[k] = 0, shadow.flags[k] = 0;
    int shadowRays = 0;
    for (int k = 0; k < kLanes; ++k) shadowRays += shadowValid[k] != 0;
    if (shadowRays > 0) rtcOccluded16(shadowValid, c.rtc, rtcContext, &shadow);
    counts->shadowRays += uint64_t(shadowRays);
    const Ints unoccluded = nearby | (load(shadow.tfar) >= 0);  // Embree sets tfar to −∞ on a hit
    const Floats lightPdf = load(qPmf) * pdfLi;
    const Floats w = powerHeuristic(lightPdf, abs(wiLocal.z) * kInvPi);
    const Floats s = (tried & unoccluded) != 0 ? abs(wiLocal.z) * w / lightPdf * kInvPi : Floats{};
    const Vec3s Li = qLe.get();
    L = L + s * Vec3s{beta.x * albedo.x * Li.x, beta.y * albedo.y * Li.y, beta.z * albedo.z * Li.z};
  }
  store3(P.Lr, P.Lg, P.Lb, L);

  // BSDF sampling: u = get2D (y drawn first), then the lobe's number uc = get1D.
  const Floats uy = uniforms(P.state, P.increment, go), ux = uniforms(P.state, P.increment, go);
  const Floats uc = uniforms(P.state, P.increment, go);
  const Ints mirror = load(kind) == PathLanes::kMirror, glass = load(kind) == PathLanes::kGlass;  // else Lambertian
  go &= wo.z != 0;
  // Lambertian: the cosine lobe on wo's side, weight ρ.
  Floats sinPhi, cosPhi;
  sinCos2Pi(uy, &sinPhi, &cosPhi);
  const Floats radius = sqrt(ux);
  Vec3s diffuse{radius * cosPhi, radius * sinPhi, sqrt(max(Floats{}, 1.0f - ux))};
  const Floats diffusePdf = diffuse.z > 0 ? diffuse.z * kInvPi : Floats{};
  diffuse.z = wo.z < 0 ? -diffuse.z : diffuse.z;
  Vec3s wiLocal = diffuse, weight = albedo;
  Floats pdf = diffusePdf, etaStep = splat(1.0f);
  Ints sampled = lambertian & (diffusePdf > 0);
  const Vec3s reflected{-wo.x, -wo.y, wo.z};  // the mirror's and the glass's reflection
  if (any(go & mirror)) {
    // The mirror's weight is Schlick's F0 + (1 − F0)(1 − |cos θ|)⁵.
    const Floats m = min(max(1.0f - abs(wo.z), Floats{}), splat(1.0f)), m5 = (m * m) * (m * m) * m;
    const Vec3s schlick{albedo.x + (1.0f - albedo.x) * m5, albedo.y + (1.0f - albedo.y) * m5, albedo.z + (1.0f - albedo.z) * m5};
    wiLocal = select(mirror, reflected, wiLocal), weight = select(mirror, schlick, weight);
    pdf = mirror != 0 ? splat(1.0f) : pdf;
    sampled |= mirror;
  }
  if (any(go & glass)) {
    // Reflect with probability F (weight 1), else refract by Snell's law (weight 1/η²).
    const Floats etaGlass = load(eta);
    const Floats F = fresnelDielectric(wo.z, etaGlass);
    const Ints reflectGlass = uc < F;
    const Ints entering = wo.z > 0;
    const Floats etaRel = entering ? etaGlass : 1.0f / etaGlass;
    const Floats normalZ = entering ? splat(1.0f) : splat(-1.0f);
    const Floats cosI = normalZ * wo.z;
    const Floats sin2T = max(Floats{}, 1.0f - cosI * cosI) / (etaRel * etaRel);
    const Floats cosT = sqrt(max(Floats{}, 1.0f - sin2T));
    const Vec3s refracted{-wo.x / etaRel, -wo.y / etaRel, -wo.z / etaRel + (cosI / etaRel - cosT) * normalZ};
    const Floats glassWeight = reflectGlass != 0 ? splat(1.0f) : 1.0f / (etaRel * etaRel);
    wiLocal = select(glass, select(reflectGlass, reflected, refracted), wiLocal);
    weight = select(glass, Vec3s{glassWeight, glassWeight, glassWeight}, weight);
    pdf = glass != 0 ? (reflectGlass != 0 ? F : 1.0f - F) : pdf;
    etaStep = glass != 0 && reflectGlass == 0 ? etaRel : etaStep;
    sampled |= glass & (reflectGlass | (sin2T < 1.0f));
  }
  go &= sampled;
  Vec3s wi;
  shading.toWorld(wiLocal.x, wiLocal.y, wiLocal.z, &wi.x, &wi.y, &wi.z);
  // Light leaks: the geometric normal must agree on reflection or transmission.
  const Ints transmitted = wiLocal.z * wo.z < 0;
  go &= (dot(wi, Ng) * dot(-d, Ng) < 0) == transmitted;
  beta = Vec3s{beta.x * weight.x, beta.y * weight.y, beta.z * weight.z};
  const Floats etaScale = load(P.etaScale) * (etaStep * etaStep);
  store(P.etaScale, etaScale);
  store(P.specular, ~lambertian);
  store(P.bsdfPdf, pdf);
  store3(P.px, P.py, P.pz, p);
  // Scene::spawnRay: offset along ±ng, to the side the ray leaves by.
  const Floats spawnOffset = dot(wi, Ng) > 0 ? splat(c.eps) : splat(-c.eps);
  store3(P.ox, P.oy, P.oz, p + spawnOffset * Ng);
  store3(P.dx, P.dy, P.dz, wi);
  store(P.tmin, Floats{}), store(P.tmax, splat(INFINITY));

  // Russian roulette from the fourth bounce: survive with q = min(1, max β · η²), then β /= q.
  const Ints depth = load(P.depth), roulette = go & (depth >= 3);
  const Floats uRoulette = uniforms(P.state, P.increment, roulette);
  const Floats q = min(splat(1.0f), max(beta.x, max(beta.y, beta.z)) * etaScale);
  const Ints survives = (q > 0) & (uRoulette < q);
  go = roulette != 0 ? go & survives : go;
  const Floats scale = (roulette & survives) != 0 ? 1.0f / q : splat(1.0f);
  store3(P.br, P.bg, P.bb, scale * beta);
  store(P.depth, depth + 1);
  const Ints ending = load(P.alive) & ~go;
  if (any(ending))
    for (int k = 0; k < kLanes; ++k)
      if (ending[k]) samples[P.sample[k]].L = Spectrum(P.Lr[k], P.Lg[k], P.Lb[k]);
  store(P.alive, go);
}

// The live paths among the first `slots` lanes of `from` move to the front of `to`, in order
// (stream compaction: full packets again). Returns how many there are.
size_t compact(const std::vector<Paths>& from, size_t slots, std::vector<Paths>& to) {
  size_t m = 0;
  for (size_t i = 0; i < slots; ++i) {
    const Paths& P = from[i / kLanes];
    const int k = int(i % kLanes);
    if (!P.alive[k]) continue;
    Paths& Q = to[m / kLanes];
    const int j = int(m % kLanes);
    Q.ox[j] = P.ox[k], Q.oy[j] = P.oy[k], Q.oz[j] = P.oz[k], Q.tmin[j] = P.tmin[k], Q.tmax[j] = P.tmax[k];
    Q.dx[j] = P.dx[k], Q.dy[j] = P.dy[k], Q.dz[j] = P.dz[k];
    Q.Lr[j] = P.Lr[k], Q.Lg[j] = P.Lg[k], Q.Lb[j] = P.Lb[k], Q.br[j] = P.br[k], Q.bg[j] = P.bg[k], Q.bb[j] = P.bb[k];
    Q.bsdfPdf[j] = P.bsdfPdf[k], Q.etaScale[j] = P.etaScale[k], Q.px[j] = P.px[k], Q.py[j] = P.py[k], Q.pz[j] = P.pz[k];
    Q.state[j] = P.state[k], Q.increment[j] = P.increment[k];
    Q.depth[j] = P.depth[k], Q.sample[j] = P.sample[k], Q.specular[j] = P.specular[k], Q.alive[j] = -1;
    ++m;
  }
  for (size_t j = m; j % kLanes != 0; ++j) to[j / kLanes].alive[j % kLanes] = 0;  // the last packet's rest
  return m;
}

PL_LANE_CLONES void traceLanes(PixelIntegrator::CameraSample* samples, int n, const Context& c) {
  const size_t packets = (size_t(n) + kLanes - 1) / kLanes;
  // Per thread, reused across rows: a row's paths and the buffer compaction moves them to.
  thread_local std::vector<Paths> paths, spare;
  if (paths.size() < packets) paths.resize(packets), spare.resize(packets);
  for (int i = 0; i < n; ++i) {
    Paths& P = paths[size_t(i) / kLanes];
    const int k = i % kLanes;
    const Ray& ray = samples[i].ray;
    P.ox[k] = ray.o.x, P.oy[k] = ray.o.y, P.oz[k] = ray.o.z, P.tmin[k] = ray.tmin, P.tmax[k] = ray.tmax;
    P.dx[k] = ray.d.x, P.dy[k] = ray.d.y, P.dz[k] = ray.d.z;
    P.Lr[k] = P.Lg[k] = P.Lb[k] = 0, P.br[k] = P.bg[k] = P.bb[k] = 1;
    P.bsdfPdf[k] = 0, P.etaScale[k] = 1, P.px[k] = ray.o.x, P.py[k] = ray.o.y, P.pz[k] = ray.o.z;
    const Rng& rng = samples[i].sampler->rng();
    P.state[k] = rng.state(), P.increment[k] = rng.increment();
    P.depth[k] = 0, P.sample[k] = i, P.specular[k] = -1;  // the camera ray sees emitters with weight 1
    P.alive[k] = -1;
  }
  for (int i = n; i % kLanes != 0; ++i) paths[size_t(i) / kLanes].alive[i % kLanes] = 0;
  // The camera rays of neighbouring pixels, and their first shadow rays (towards the same lights
  // from nearby points), are coherent: Embree traverses such packets together.
  RTCIntersectContext incoherent, coherent;
  rtcInitIntersectContext(&incoherent);
  rtcInitIntersectContext(&coherent);
  coherent.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  Counts counts;
  // A bounce: every packet's rays first, then every packet's shading, each fetching the next
  // packet's triangle records while it works, so that their cache misses are over by then.
  thread_local std::vector<RTCRayHit16> hits;
  struct alignas(64) Mask {  // Embree reads a packet's valid lanes from 64-byte-aligned memory
    int32_t lanes[kLanes];
  };
  thread_local std::vector<Mask> valid;
  if (hits.size() < packets) hits.resize(packets), valid.resize(packets);
  // The paths occupy the first `slots` lanes, the ended ones among them marked dead; after each
  // bounce the live ones are squeezed together, so that every packet but the last is full.
  // (Squeezing only once an eighth or a quarter of the lanes had died measured the same.)
  for (size_t slots = size_t(n), bounces = 0; slots > 0; ++bounces) {
    RTCIntersectContext* context = bounces == 0 ? &coherent : &incoherent;
    const size_t used = (slots + kLanes - 1) / kLanes;
    for (size_t g = 0; g < used; ++g) intersect(paths[g], c, context, &hits[g], valid[g].lanes, &counts);
    prefetch(hits[0], valid[0].lanes, c);
    size_t live = 0;
    for (size_t g = 0; g < used; ++g) {
      if (g + 1 < used) prefetch(hits[g + 1], valid[g + 1].lanes, c);
      shade(paths[g], hits[g], valid[g].lanes, c, context, samples, &counts);
      for (int k = 0; k < kLanes; ++k) live += paths[g].alive[k] != 0;
    }
    if (live == 0) break;
    if (live < slots) {
      slots = compact(paths, slots, spare);
      paths.swap(spare);
    }
  }
  Scene::countRays(counts.rays, counts.shadowRays);
}

}  // namespace

void PathLanes::trace(PixelIntegrator::CameraSample* samples, int n, int maxDepth) const {
  const Context c{triangles_, normals_, surfaces_, emitters_, scene_.lightDistribution(), rtc_, scene_.epsilon(), maxDepth};
  traceLanes(samples, n, c);
}

}  // namespace pl
