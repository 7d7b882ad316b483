// The least path loop's 16-lane kernel: bench/least_path_loop_simd.cpp's opening comment says
// what it computes. Included once per instruction set by core/lanes_copies.h (no include guard),
// into namespace pl::least_simd::PL_LANES_ISA; everything it uses is included by
// least_path_loop_simd.cpp.
#include "core/lanes.h"

namespace pl::least_simd::PL_LANES_ISA {
namespace {

using namespace lanes::PL_LANES_ISA;

// 16 paths' state, one array per quantity (structure of arrays).
struct alignas(64) Lanes {
  float ox[kLanes], oy[kLanes], oz[kLanes];  // the next ray
  float dx[kLanes], dy[kLanes], dz[kLanes];
  float Lr[kLanes], Lg[kLanes], Lb[kLanes];  // radiance so far
  float br[kLanes], bg[kLanes], bb[kLanes];  // throughput β
  float bsdfPdf[kLanes];                     // of the direction that made the ray
  uint64_t state[kLanes], increment[kLanes]; // each path's PCG32 stream (Rng)
  int32_t depth[kLanes], pixel[kLanes], cameraRay[kLanes], alive[kLanes];
};

// Rng::uniform() for the lanes where `draw` is set.
PL_HOT_INLINE Floats uniforms(Lanes& P, Ints draw) { return lanes::PL_LANES_ISA::uniforms(P.state, P.increment, draw); }

struct RowCounts {
  uint64_t rays = 0, shadowRays = 0;
};

// One bounce of the 16 paths in P (lanes [0, live) hold paths): intersect, add emission, next-
// event estimation, BSDF sampling, roulette. Sets P.alive for the paths that go on.
PL_HOT_INLINE void bounce(Lanes& P, int live, const LeastPathScene& least, const AliasTable& lightPick, float eps, int maxDepth,
                          RTCIntersectContext* context, RowCounts* counts) {
  const std::vector<LeastTriangle>& triangles = least.triangles;
  alignas(64) int32_t valid[kLanes];
  for (int k = 0; k < kLanes; ++k) valid[k] = k < live ? -1 : 0;
  alignas(64) RTCRayHit16 rh;
  // Lanes past `live` hold finished paths' stale values: they get a finite ray with tfar < tnear
  // (see the shadow rays below for why the valid mask alone does not do).
  const Ints on = load(valid) != 0;
  store(rh.ray.org_x, on ? load(P.ox) : Floats{}), store(rh.ray.org_y, on ? load(P.oy) : Floats{});
  store(rh.ray.org_z, on ? load(P.oz) : Floats{});
  store(rh.ray.dir_x, on ? load(P.dx) : Floats{}), store(rh.ray.dir_y, on ? load(P.dy) : Floats{});
  store(rh.ray.dir_z, on ? load(P.dz) : splat(1.0f));
  store(rh.ray.tnear, Floats{}), store(rh.ray.tfar, on ? splat(INFINITY) : splat(-INFINITY)), store(rh.ray.time, Floats{});
  for (int k = 0; k < kLanes; ++k)
    rh.ray.mask[k] = 0xFFFFFFFFu, rh.ray.id[k] = 0, rh.ray.flags[k] = 0, rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect16(valid, least.rtc, context, &rh);
  counts->rays += uint64_t(live);

  // The hit triangles' records, gathered lane by lane (a miss reads triangle 0, unused).
  alignas(64) float nx[kLanes], ny[kLanes], nz[kLanes], ar[kLanes], ag[kLanes], ab[kLanes], er[kLanes], eg[kLanes], eb[kLanes];
  alignas(64) float area[kLanes], emitterPmf[kLanes];
  alignas(64) int32_t hit[kLanes], emits[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    hit[k] = valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? -1 : 0;
    const LeastTriangle& tri = triangles[hit[k] ? rh.hit.primID[k] : 0];
    nx[k] = tri.n.x, ny[k] = tri.n.y, nz[k] = tri.n.z;
    ar[k] = tri.albedo.x, ag[k] = tri.albedo.y, ab[k] = tri.albedo.z;
    er[k] = tri.Le.x, eg[k] = tri.Le.y, eb[k] = tri.Le.z;
    area[k] = tri.area;
    emits[k] = tri.light >= 0 ? -1 : 0;
    emitterPmf[k] = tri.light >= 0 ? lightPick.pmf(size_t(tri.light)) : 0.0f;
  }
  const Floats dx = load(P.dx), dy = load(P.dy), dz = load(P.dz), t = load(rh.ray.tfar);
  const Floats px = load(P.ox) + t * dx, py = load(P.oy) + t * dy, pz = load(P.oz) + t * dz;
  const Floats Nx = load(nx), Ny = load(ny), Nz = load(nz);
  const Floats cosFront = -(Nx * dx + Ny * dy + Nz * dz);  // > 0: the ray meets the front face
  const Floats br = load(P.br), bg = load(P.bg), bb = load(P.bb);
  Floats Lr = load(P.Lr), Lg = load(P.Lg), Lb = load(P.Lb);

  // Emission found by BSDF sampling, weighted against next-event estimation's density for the
  // same point, p_light = pmf · r² / (A cos θ_light); seen from the camera, weight 1.
  {
    const Floats lightPdf = load(emitterPmf) * t * t / (load(area) * cosFront);
    const Floats a = load(P.bsdfPdf) * load(P.bsdfPdf), b = lightPdf * lightPdf;
    Floats w = load(P.cameraRay) != 0 ? splat(1.0f) : a / (a + b);
    w = (load(hit) & load(emits) & (cosFront > 0)) != 0 ? w : Floats{};
    Lr += br * load(er) * w, Lg += bg * load(eg) * w, Lb += bb * load(eb) * w;
  }
  Ints go = load(hit) & (load(P.depth) < maxDepth);
  const Floats side = cosFront > 0 ? splat(1.0f) : splat(-1.0f);  // the side the ray arrived on
  const Floats sx = side * Nx, sy = side * Ny, sz = side * Nz;

  // Next-event estimation: a light by power, a point uniform on it (Heitz's triangle map), one
  // shadow ray from the offset point to one epsilon short of it.
  const Floats uLight = uniforms(P, go), v = uniforms(P, go), u = uniforms(P, go);
  alignas(64) float q0x[kLanes], q0y[kLanes], q0z[kLanes], q1x[kLanes], q1y[kLanes], q1z[kLanes], q2x[kLanes], q2y[kLanes], q2z[kLanes];
  alignas(64) float lnx[kLanes], lny[kLanes], lnz[kLanes], larea[kLanes], lr[kLanes], lg[kLanes], lb[kLanes], pmf[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    const LeastTriangle& light = triangles[least.lightTriangle[lightPick.sample(uLight[k], &pmf[k])]];
    q0x[k] = light.p0.x, q0y[k] = light.p0.y, q0z[k] = light.p0.z;
    q1x[k] = light.p1.x, q1y[k] = light.p1.y, q1z[k] = light.p1.z;
    q2x[k] = light.p2.x, q2y[k] = light.p2.y, q2z[k] = light.p2.z;
    lnx[k] = light.n.x, lny[k] = light.n.y, lnz[k] = light.n.z;
    larea[k] = light.area, lr[k] = light.Le.x, lg[k] = light.Le.y, lb[k] = light.Le.z;
  }
  const Ints lower = u < v;
  const Floats b1 = lower ? u * 0.5f : u - v * 0.5f, b2 = lower ? v - u * 0.5f : v * 0.5f, b0 = 1.0f - b1 - b2;
  const Floats tx = b1 * load(q0x) + b2 * load(q1x) + b0 * load(q2x);
  const Floats ty = b1 * load(q0y) + b2 * load(q1y) + b0 * load(q2y);
  const Floats tz = b1 * load(q0z) + b2 * load(q1z) + b0 * load(q2z);
  const Floats lx = tx - px, ly = ty - py, lz = tz - pz;
  const Floats r2 = lx * lx + ly * ly + lz * lz, invDistance = 1.0f / sqrt(r2);
  const Floats wx = lx * invDistance, wy = ly * invDistance, wz = lz * invDistance;
  const Floats cosSurface = sx * wx + sy * wy + sz * wz;
  const Floats cosLight = -(load(lnx) * wx + load(lny) * wy + load(lnz) * wz);
  const Ints shadowed = go & (cosSurface > 0) & (cosLight > 0);
  alignas(64) RTCRay16 shadow;
  const Floats ox = px + eps * sx, oy = py + eps * sy, oz = pz + eps * sz;
  const Floats sdx = tx - ox, sdy = ty - oy, sdz = tz - oz;
  const Floats length = sqrt(sdx * sdx + sdy * sdy + sdz * sdz), invLength = 1.0f / length;
  // Lanes without a shadow ray get a finite ray with tfar < tnear: Embree's packet-splitting
  // path on CPUs without AVX-512 checks every lane it deems active (tnear ≤ tfar) for finite
  // values, whatever the valid mask says, and a missed path's lane holds an infinite origin.
  const Ints casts = shadowed != 0;
  store(shadow.org_x, casts ? ox : Floats{}), store(shadow.org_y, casts ? oy : Floats{}), store(shadow.org_z, casts ? oz : Floats{});
  store(shadow.dir_x, casts ? sdx * invLength : Floats{}), store(shadow.dir_y, casts ? sdy * invLength : Floats{});
  store(shadow.dir_z, casts ? sdz * invLength : splat(1.0f));
  store(shadow.tnear, Floats{}), store(shadow.tfar, casts ? length - eps : splat(-INFINITY)), store(shadow.time, Floats{});
  for (int k = 0; k < kLanes; ++k) shadow.mask[k] = 0xFFFFFFFFu, shadow.id[k] = 0, shadow.flags[k] = 0;
  alignas(64) int32_t shadowValid[kLanes];
  store(shadowValid, shadowed);
  int shadowRays = 0;
  for (int k = 0; k < kLanes; ++k) shadowRays += shadowValid[k] != 0;
  if (shadowRays > 0) {
    rtcOccluded16(shadowValid, least.rtc, context, &shadow);
    counts->shadowRays += uint64_t(shadowRays);
    // f · Le · cos θ · w / p_light, with f = ρ/π and the power heuristic against cos θ/π.
    const Floats lightPdf = load(pmf) * r2 / (load(larea) * cosLight);
    const Floats bsdfPdf = cosSurface * kInvPi, a = lightPdf * lightPdf;
    const Floats w = a / (a + bsdfPdf * bsdfPdf);
    const Ints lit = shadowed & (load(shadow.tfar) >= 0);  // Embree sets tfar to −∞ on a hit
    const Floats s = lit != 0 ? cosSurface * w / lightPdf * kInvPi : Floats{};
    Lr += br * load(ar) * load(lr) * s, Lg += bg * load(ag) * load(lg) * s, Lb += bb * load(ab) * load(lb) * s;
  }
  store(P.Lr, Lr), store(P.Lg, Lg), store(P.Lb, Lb);

  // BSDF sampling, cosine-weighted (Malley): f cos θ / p = ρ. The local direction goes to world
  // space through Duff et al.'s basis around the normal (core/frame.h).
  const Floats phi = uniforms(P, go), radius2 = uniforms(P, go);
  Floats sinPhi, cosPhi;
  sinCos2Pi(phi, &sinPhi, &cosPhi);
  const Floats r = sqrt(radius2);
  const Floats localX = r * cosPhi, localY = r * sinPhi, localZ = sqrt(max(Floats{}, 1.0f - radius2));
  Floats dirX, dirY, dirZ;
  Frames(sx, sy, sz).toWorld(localX, localY, localZ, &dirX, &dirY, &dirZ);
  store(P.dx, dirX), store(P.dy, dirY), store(P.dz, dirZ);
  const Floats bsdfPdf = localZ * kInvPi;
  store(P.bsdfPdf, bsdfPdf);
  go &= bsdfPdf > 0;
  Floats nbr = br * load(ar), nbg = bg * load(ag), nbb = bb * load(ab);
  store(P.cameraRay, Ints{});
  store(P.ox, px + eps * sx), store(P.oy, py + eps * sy), store(P.oz, pz + eps * sz);

  // Russian roulette by throughput (core/roulette.h) from the fourth bounce: continue with
  // q = min(1, max β), divide by q.
  const Ints depth = load(P.depth), roulette = go & (depth >= 3);
  const Floats uRoulette = uniforms(P, roulette);
  const Floats q = min(splat(1.0f), max(nbr, max(nbg, nbb)));
  const Ints survives = (q > 0) & (uRoulette < q);
  go = roulette != 0 ? go & survives : go;
  const Floats scale = (roulette & survives) != 0 ? 1.0f / q : splat(1.0f);
  store(P.br, nbr * scale), store(P.bg, nbg * scale), store(P.bb, nbb * scale);
  store(P.depth, depth + 1);
  store(P.alive, go);
}

// Paths [0, n) of `from` that are alive move to the front of `to`, in order; the others' radiance
// goes to L by pixel. Returns how many go on.
size_t compact(const std::vector<Lanes>& from, size_t n, std::vector<Lanes>& to, Vec3* L) {
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const Lanes& P = from[i / kLanes];
    const int k = int(i % kLanes);
    if (!P.alive[k]) {
      L[P.pixel[k]] = Vec3(P.Lr[k], P.Lg[k], P.Lb[k]);
      continue;
    }
    Lanes& Q = to[m / kLanes];
    const int j = int(m % kLanes);
    Q.ox[j] = P.ox[k], Q.oy[j] = P.oy[k], Q.oz[j] = P.oz[k], Q.dx[j] = P.dx[k], Q.dy[j] = P.dy[k], Q.dz[j] = P.dz[k];
    Q.Lr[j] = P.Lr[k], Q.Lg[j] = P.Lg[k], Q.Lb[j] = P.Lb[k], Q.br[j] = P.br[k], Q.bg[j] = P.bg[k], Q.bb[j] = P.bb[k];
    Q.bsdfPdf[j] = P.bsdfPdf[k], Q.state[j] = P.state[k], Q.increment[j] = P.increment[k];
    Q.depth[j] = P.depth[k], Q.pixel[j] = P.pixel[k], Q.cameraRay[j] = P.cameraRay[k];
    ++m;
  }
  return m;
}

// Row y's paths for sample s, one per pixel; their radiance into L[x].
void traceRow(const Scene& scene, const LeastPathScene& least, int y, int s, int width, int height, int maxDepth,
              uint64_t seed, std::vector<Lanes>& paths, std::vector<Lanes>& spare, Vec3* L, RowCounts* counts) {
  const AliasTable& lightPick = scene.lightDistribution();
  const float eps = scene.epsilon();
  for (int x = 0; x < width; ++x) {
    Lanes& P = paths[size_t(x) / kLanes];
    const int k = x % kLanes;
    Rng rng = Rng::keyed(seed, uint64_t(y) * width + x, uint64_t(s));
    const float jx = rng.uniform(), jy = rng.uniform();
    const Ray ray = scene.cameraRay(x + jx, float(y) + jy, width, height);
    P.ox[k] = ray.o.x, P.oy[k] = ray.o.y, P.oz[k] = ray.o.z, P.dx[k] = ray.d.x, P.dy[k] = ray.d.y, P.dz[k] = ray.d.z;
    P.Lr[k] = P.Lg[k] = P.Lb[k] = 0, P.br[k] = P.bg[k] = P.bb[k] = 1, P.bsdfPdf[k] = 0;
    P.state[k] = rng.state(), P.increment[k] = rng.increment();
    P.depth[k] = 0, P.pixel[k] = x, P.cameraRay[k] = 1;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (size_t live = size_t(width); live > 0;) {
    for (size_t first = 0; first < live; first += kLanes)
      bounce(paths[first / kLanes], int(std::min<size_t>(kLanes, live - first)), least, lightPick, eps, maxDepth, &context, counts);
    live = compact(paths, live, spare, L);
    paths.swap(spare);
  }
}

// The image's rows in parallel: each row's samples one pass at a time, its pixel means into
// result->image, its counts and sums into rows.
void traceRows(const Scene& scene, const LeastPathScene& least, int width, int height, int spp, int maxDepth, int threads,
               uint64_t seed, LeastPathResult* result, LeastRowCounts* rows) {
  parallelFor(size_t(height), threads, [&](size_t y, int) {
    const size_t packets = (size_t(width) + kLanes - 1) / kLanes;
    std::vector<Lanes> paths(packets), spare(packets);
    std::vector<Vec3> L(size_t(width), Vec3(0.0f));
    std::vector<glm::dvec3> pixelSum(size_t(width), glm::dvec3(0.0));
    RowCounts counts;
    double sum = 0, sumSquares = 0;
    for (int s = 0; s < spp; ++s) {
      traceRow(scene, least, int(y), s, width, height, maxDepth, seed, paths, spare, L.data(), &counts);
      for (int x = 0; x < width; ++x) {
        pixelSum[size_t(x)] += glm::dvec3(L[size_t(x)]);
        const double m = (double(L[size_t(x)].x) + L[size_t(x)].y + L[size_t(x)].z) / 3;
        sum += m, sumSquares += m * m;
      }
    }
    for (int x = 0; x < width; ++x) result->image[y * size_t(width) + size_t(x)] = Vec3(pixelSum[size_t(x)] / double(spp));
    rows->rays[y] = counts.rays, rows->shadowRays[y] = counts.shadowRays;
    rows->sum[y] = sum, rows->sumSquares[y] = sumSquares;
  });
}

}  // namespace
}  // namespace pl::least_simd::PL_LANES_ISA
