// The path tracer's kernel in 16 SIMD lanes: integrators/path_lanes.cpp's opening comment says
// what it computes. Included once per instruction set by core/lanes_copies.h (no include guard),
// into namespace pl::path_lanes::PL_LANES_ISA; everything it uses is included by path_lanes.cpp.
#include "core/lanes.h"

namespace pl::path_lanes::PL_LANES_ISA {
namespace {

using namespace lanes::PL_LANES_ISA;

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

// What the flat lanes among smooth ones read as vertex normals (their ng stays).
const PathLanes::Normals kNoNormals{};

// A field of one of a few records (materials, lights) for each lane's index: by selects over the
// records when they are few (nothing goes through memory), lane by lane otherwise.
template <class V, class Record, class Field>
PL_HOT_INLINE V pick(const std::vector<Record>& table, Ints index, Field field) {
  V out{};
  if (table.size() <= 8) {
    for (size_t r = 0; r < table.size(); ++r) out = index == int32_t(r) ? V{} + field(table[r]) : out;
  } else {
    for (int k = 0; k < kLanes; ++k) out[k] = field(table[size_t(index[k])]);
  }
  return out;
}
template <class Record>
PL_HOT_INLINE Vec3s pick3(const std::vector<Record>& table, Ints index, Vec3 Record::*field) {
  return {pick<Floats>(table, index, [&](const Record& r) { return (r.*field).x; }),
          pick<Floats>(table, index, [&](const Record& r) { return (r.*field).y; }),
          pick<Floats>(table, index, [&](const Record& r) { return (r.*field).z; })};
}

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


// The closest hits of the rays of P's live lanes, into rh; `valid` marks the lanes traced.
PL_HOT_INLINE void intersect(const Paths& P, const Context& c, RTCIntersectContext* rtcContext, RTCRayHit16* rh, int32_t* valid,
                             Counts* counts) {
  const Vec3s o = load3(P.ox, P.oy, P.oz), d = load3(P.dx, P.dy, P.dz);
  const Ints on = load(P.alive) & embreeValid(o, d);
  store(valid, on);
  // Lanes not traced get a finite ray with tfar < tnear: on CPUs without AVX-512, Embree splits
  // the packet in two of 8 and asserts that every lane it deems active (tnear <= tfar) is
  // finite, whatever the valid mask says; a finished path's lane may hold anything.
  store(rh->ray.org_x, on ? o.x : Floats{}), store(rh->ray.org_y, on ? o.y : Floats{}), store(rh->ray.org_z, on ? o.z : Floats{});
  store(rh->ray.dir_x, on ? d.x : Floats{}), store(rh->ray.dir_y, on ? d.y : Floats{}), store(rh->ray.dir_z, on ? d.z : splat(1.0f));
  store(rh->ray.tnear, on ? load(P.tmin) : Floats{}), store(rh->ray.tfar, on ? load(P.tmax) : splat(-INFINITY));
  store(rh->ray.time, Floats{});
  for (int k = 0; k < kLanes; ++k)
    rh->ray.mask[k] = 0xFFFFFFFFu, rh->ray.id[k] = 0, rh->ray.flags[k] = 0, rh->hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  int rays = 0;
  for (int k = 0; k < kLanes; ++k) rays += valid[k] != 0;
  if (rays > 0) rtcIntersect16(valid, c.rtc, rtcContext, rh);
  counts->rays += uint64_t(rays);
}

// The rest of a bounce for P's live lanes, whose rays' hits are rh (`valid`: the lanes traced).
// The paths that end give their radiance to their camera samples; P.alive keeps the others.
PL_HOT_INLINE void shade(Paths& P, const RTCRayHit16& rh, const int32_t* valid, const Context& c, RTCIntersectContext* rtcContext,
                         PixelIntegrator::CameraSample* samples, Counts* counts) {
  const Vec3s d = load3(P.dx, P.dy, P.dz);
  // The hits' triangles (a miss reads record 0): each record is one cache line, read whole.
  alignas(64) int32_t hit[kLanes];
  const void* records[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    hit[k] = valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? -1 : 0;
    records[k] = &c.triangles[hit[k] ? c.firstTriangle[rh.hit.geomID[k]] + rh.hit.primID[k] : 0];
  }
  Floats field[kLanes];  // PathLanes::Triangle's words
  gatherRecords(records, field);
  const Vec3s p0{field[0], field[1], field[2]}, p1{field[3], field[4], field[5]}, p2{field[6], field[7], field[8]};
  const Vec3s Ng{field[9], field[10], field[11]};
  const Ints normalsAt = bitsOf(field[12]), material = bitsOf(field[13]), lightIndex = bitsOf(field[14]);
  // Their materials.
  using Surface = PathLanes::Surface;
  const Ints kind = pick<Ints>(c.surfaces, material, [](const Surface& m) { return m.kind; });
  const Vec3s albedo = pick3(c.surfaces, material, &Surface::color);  // ρ, or the mirror's F0
  const Floats eta = pick<Floats>(c.surfaces, material, [](const Surface& m) { return m.eta; });
  // The hit: p = b0 v0 + b1 v1 + b2 v2 with Embree's (u, v) = (b1, b2); the shading normal is
  // the vertex normals' interpolation, normalised (the geometric one without them).
  const Floats b1 = load(rh.hit.u), b2 = load(rh.hit.v), b0 = 1.0f - b1 - b2;
  const Vec3s p = b0 * p0 + b1 * p1 + b2 * p2;
  const Ints isHit = load(hit), isSmooth = isHit & (normalsAt >= 0);
  Vec3s ns = Ng;
  if (any(isSmooth)) {
    const void* normalRecords[kLanes];
    for (int k = 0; k < kLanes; ++k) normalRecords[k] = isSmooth[k] ? &c.normals[size_t(normalsAt[k])] : &kNoNormals;
    Floats nf[kLanes];
    gatherRecords(normalRecords, nf);
    const Vec3s n0{nf[0], nf[1], nf[2]}, n1{nf[3], nf[4], nf[5]}, n2{nf[6], nf[7], nf[8]};
    const Vec3s n = b0 * n0 + b1 * n1 + b2 * n2;
    const Floats length = sqrt(dot(n, n));
    ns = select(isSmooth & (length > 0), (1.0f / length) * n, Ng);
  }

  Vec3s L = load3(P.Lr, P.Lg, P.Lb);
  Vec3s beta = load3(P.br, P.bg, P.bb);

  // Emission found by BSDF sampling (AreaLight::L: the front face, or both), weighted against
  // next-event estimation's density from the previous vertex, pmf · r² / (A |cos θ_light|).
  const Ints emits = isHit & (lightIndex >= 0);
  if (any(emits)) {
    using Emitter = PathLanes::Emitter;
    const Ints light = emits != 0 ? lightIndex : Ints{};
    const Vec3s lightN = pick3(c.emitters, light, &Emitter::n), Le = pick3(c.emitters, light, &Emitter::Le);
    const Floats lightArea = pick<Floats>(c.emitters, light, [](const Emitter& e) { return e.area; });
    const Floats lightPmf = pick<Floats>(c.emitters, light, [](const Emitter& e) { return e.pmf; });
    const Ints twoSided = pick<Ints>(c.emitters, light, [](const Emitter& e) { return e.twoSided; });
    const Floats cosEmit = -dot(lightN, d);
    const Ints lit = emits & ((cosEmit > 0) | ((twoSided != 0) & (cosEmit < 0)));
    const Vec3s toHit = p - load3(P.px, P.py, P.pz);
    const Floats r2 = dot(toHit, toHit);
    const Floats cosLight = abs(dot(lightN, toHit)) / sqrt(r2);
    const Floats pdfLi = (cosLight > 0) & (lightArea > 0) ? r2 / (lightArea * cosLight) : Floats{};
    const Floats w = load(P.specular) != 0 ? splat(1.0f) : powerHeuristic(load(P.bsdfPdf), lightPmf * pdfLi);
    const Floats wLit = lit != 0 ? w : Floats{};
    L = L + wLit * Vec3s{beta.x * Le.x, beta.y * Le.y, beta.z * Le.z};
  }
  Ints go = isHit & (load(P.depth) < c.maxDepth);
  const Ints lambertian = kind == PathLanes::kLambertian;

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
    alignas(64) int32_t picked[kLanes];
    alignas(64) float pickPmf[kLanes];
    for (int k = 0; k < kLanes; ++k) {
      float pmf = 0;
      picked[k] = nee[k] ? int32_t(c.lightPick.sample(uLight[k], &pmf)) : 0;
      pickPmf[k] = pmf;
    }
    using Emitter = PathLanes::Emitter;
    const Ints light = load(picked);
    const Vec3s q0 = pick3(c.emitters, light, &Emitter::p0), q1 = pick3(c.emitters, light, &Emitter::p1);
    const Vec3s q2 = pick3(c.emitters, light, &Emitter::p2), qn = pick3(c.emitters, light, &Emitter::n);
    const Vec3s qLe = pick3(c.emitters, light, &Emitter::Le);
    const Floats qArea = pick<Floats>(c.emitters, light, [](const Emitter& e) { return e.area; });
    const Ints qTwoSided = pick<Ints>(c.emitters, light, [](const Emitter& e) { return e.twoSided; });
    const Floats qPmf = load(pickPmf);
    // AreaLight::sampleLi: Heitz's triangle map, y = bx p0 + by p1 + (1 − bx − by) p2.
    const Ints lower = ux < uy;
    const Floats bx = lower ? ux * 0.5f : ux - uy * 0.5f, by = lower ? uy - ux * 0.5f : uy * 0.5f;
    const Vec3s y = bx * q0 + by * q1 + (1.0f - bx - by) * q2;
    const Vec3s toLight = y - p;
    const Floats r2 = dot(toLight, toLight), distance = sqrt(r2);
    const Vec3s wi = (1.0f / distance) * toLight;
    const Floats cosLight = -dot(qn, wi);
    const Ints emitting = (cosLight > 0) | ((qTwoSided != 0) & (cosLight < 0));
    const Floats pdfLi = r2 / (qArea * abs(cosLight));
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
    const Ints casts = tried & ~nearby;
    store(shadowValid, casts);
    alignas(64) RTCRay16 shadow;
    const Vec3s dir = (1.0f / length) * toTarget;
    // Lanes without a shadow ray get a finite one with tfar < tnear (see intersect()).
    store(shadow.org_x, casts ? origin.x : Floats{}), store(shadow.org_y, casts ? origin.y : Floats{});
    store(shadow.org_z, casts ? origin.z : Floats{});
    store(shadow.dir_x, casts ? dir.x : Floats{}), store(shadow.dir_y, casts ? dir.y : Floats{});
    store(shadow.dir_z, casts ? dir.z : splat(1.0f));
    store(shadow.tnear, Floats{}), store(shadow.tfar, casts ? length - c.eps : splat(-INFINITY)), store(shadow.time, Floats{});
    for (int k = 0; k < kLanes; ++k) shadow.mask[k] = 0xFFFFFFFFu, shadow.id[k] = 0, shadow.flags[k] = 0;
    int shadowRays = 0;
    for (int k = 0; k < kLanes; ++k) shadowRays += shadowValid[k] != 0;
    if (shadowRays > 0) rtcOccluded16(shadowValid, c.rtc, rtcContext, &shadow);
    counts->shadowRays += uint64_t(shadowRays);
    const Ints unoccluded = nearby | (load(shadow.tfar) >= 0);  // Embree sets tfar to −∞ on a hit
    const Floats lightPdf = qPmf * pdfLi;
    const Floats w = powerHeuristic(lightPdf, abs(wiLocal.z) * kInvPi);
    const Floats s = (tried & unoccluded) != 0 ? abs(wiLocal.z) * w / lightPdf * kInvPi : Floats{};
    L = L + s * Vec3s{beta.x * albedo.x * qLe.x, beta.y * albedo.y * qLe.y, beta.z * albedo.z * qLe.z};
  }
  store3(P.Lr, P.Lg, P.Lb, L);

  // BSDF sampling: u = get2D (y drawn first), then the lobe's number uc = get1D.
  const Floats uy = uniforms(P.state, P.increment, go), ux = uniforms(P.state, P.increment, go);
  const Floats uc = uniforms(P.state, P.increment, go);
  const Ints mirror = kind == PathLanes::kMirror, glass = kind == PathLanes::kGlass;  // else Lambertian
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
    const Floats F = fresnelDielectric(wo.z, eta);
    const Ints reflectGlass = uc < F;
    const Ints entering = wo.z > 0;
    const Floats etaRel = entering ? eta : 1.0f / eta;
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

  // Russian roulette by throughput (core/roulette.h) from the fourth bounce: survive with
  // q = min(1, max β · η²), then β /= q.
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

// Path j's state into lane i (of other packets or the same).
PL_HOT_INLINE void move(std::vector<Paths>& paths, size_t j, size_t i) {
  const Paths& P = paths[j / kLanes];
  Paths& Q = paths[i / kLanes];
  const int k = int(j % kLanes), l = int(i % kLanes);
  Q.ox[l] = P.ox[k], Q.oy[l] = P.oy[k], Q.oz[l] = P.oz[k], Q.tmin[l] = P.tmin[k], Q.tmax[l] = P.tmax[k];
  Q.dx[l] = P.dx[k], Q.dy[l] = P.dy[k], Q.dz[l] = P.dz[k];
  Q.Lr[l] = P.Lr[k], Q.Lg[l] = P.Lg[k], Q.Lb[l] = P.Lb[k], Q.br[l] = P.br[k], Q.bg[l] = P.bg[k], Q.bb[l] = P.bb[k];
  Q.bsdfPdf[l] = P.bsdfPdf[k], Q.etaScale[l] = P.etaScale[k], Q.px[l] = P.px[k], Q.py[l] = P.py[k], Q.pz[l] = P.pz[k];
  Q.state[l] = P.state[k], Q.increment[l] = P.increment[k];
  Q.depth[l] = P.depth[k], Q.sample[l] = P.sample[k], Q.specular[l] = P.specular[k], Q.alive[l] = P.alive[k];
}

// Stream compaction: the live paths among the first `slots` lanes fill the lanes of the ended
// ones, the last live path moving into the first hole, so that they occupy the first lanes
// (full packets again) at the cost of one copy per hole, not per path. Returns how many live.
size_t compact(std::vector<Paths>& paths, size_t slots) {
  auto alive = [&](size_t i) { return paths[i / kLanes].alive[i % kLanes] != 0; };
  size_t hole = 0, last = slots;
  for (;;) {
    while (hole < last && alive(hole)) ++hole;
    while (last > hole && !alive(last - 1)) --last;
    if (hole + 1 >= last) break;
    move(paths, last - 1, hole);
    paths[(last - 1) / kLanes].alive[(last - 1) % kLanes] = 0;
    --last;
  }
  const size_t live = hole < last ? last : hole;
  for (size_t j = live; j % kLanes != 0; ++j) paths[j / kLanes].alive[j % kLanes] = 0;  // the last packet's rest
  return live;
}

void traceLanes(PixelIntegrator::CameraSample* samples, int n, const Context& c) {
  const size_t packets = (size_t(n) + kLanes - 1) / kLanes;
  // A row's paths, per thread, reused from row to row.
  thread_local std::vector<Paths> paths;
  if (paths.size() < packets) paths.resize(packets);
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
  // The paths occupy the first `slots` lanes, the ended ones among them marked dead; after each
  // bounce the live ones are squeezed together, so that every packet but the last is full.
  // (Squeezing only once an eighth or a quarter of the lanes had died measured the same.)
  for (size_t slots = size_t(n), bounces = 0; slots > 0; ++bounces) {
    RTCIntersectContext* context = bounces == 0 ? &coherent : &incoherent;
    size_t live = 0;
    for (size_t g = 0; g < (slots + kLanes - 1) / kLanes; ++g) {
      alignas(64) RTCRayHit16 hits;
      alignas(64) int32_t valid[kLanes];  // Embree reads a packet's lanes from 64-byte-aligned memory
      intersect(paths[g], c, context, &hits, valid, &counts);
      shade(paths[g], hits, valid, c, context, samples, &counts);
      for (int k = 0; k < kLanes; ++k) live += paths[g].alive[k] != 0;
    }
    if (live == 0) break;
    if (live < slots) slots = compact(paths, slots);
  }
  Scene::countRays(counts.rays, counts.shadowRays);
}

}  // namespace
}  // namespace pl::path_lanes::PL_LANES_ISA
