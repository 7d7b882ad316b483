#include "bench/least_path_loop.h"

#include <chrono>
#include <cmath>
#include <unordered_map>

#include "core/roulette.h"
#include "bench/least_path_scene.h"
#include "bsdfs/lambertian.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "render/integrator.h"

namespace pl {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::string leastPathLoopUnsupported(const Scene& scene) {
  if (scene.environment()) return "an environment light";
  if (scene.hasAbsorbingVolumes()) return "an absorbing volume";
  for (const auto& light : scene.lights())
    if (light->type() != LightType::kArea) return std::string("a ") + light->name() + " light";
  // The materials triangles use (the loader keeps a default one that may have none).
  std::vector<bool> used(scene.materials().size(), false);
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) used[scene.triangleMaterial(t)] = true;
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials()[i];
    if (!m.bsdf || m.bsdf->bsdfClass() != BSDFClass::kLambertian) return "material '" + m.name + "' is not Lambertian";
    if (!static_cast<const Lambertian&>(*m.bsdf).albedo().isConstant()) return "material '" + m.name + "' is textured";
    if (m.normalMap || m.alpha || m.alphaMode != AlphaMode::Opaque) return "material '" + m.name + "' has a normal map or alpha";
    if (m.emissionTexture || (m.twoSided && m.emission != Spectrum(0.0f))) return "material '" + m.name + "' emits from a texture or both faces";
  }
  // Interpolated normals and vertex colours, triangle by triangle (at the corners and the centre).
  const Vec2 at[4] = {{0, 0}, {1, 0}, {0, 1}, {1.0f / 3, 1.0f / 3}};
  for (uint32_t t = 0; t < scene.triangleCount(); ++t)
    for (const Vec2& b : at) {
      const SurfaceHit hit = scene.surfaceAt(t, b.x, b.y);
      if (hit.shadingDiffers()) return "triangle " + std::to_string(t) + " has shading normals";
      if (hit.color != Spectrum(1.0f)) return "triangle " + std::to_string(t) + " has a vertex colour";
    }
  return {};
}

LeastPathScene::LeastPathScene(const Scene& scene) {
  if (const std::string why = leastPathLoopUnsupported(scene); !why.empty()) throw Error("least path loop: " + why);
  // Triangles in one flat array, indexed by Embree's primID on a scene of its own.
  const uint32_t count = uint32_t(scene.triangleCount());
  triangles.resize(count);
  lightTriangle.assign(scene.lights().size(), 0);
  std::unordered_map<const Light*, int> lightIndex;
  for (size_t i = 0; i < scene.lights().size(); ++i) lightIndex[scene.lights()[i].get()] = int(i);
  for (uint32_t t = 0; t < count; ++t) {
    LeastTriangle& tri = triangles[t];
    const auto v = scene.trianglePositions(t);
    tri.p0 = v[0], tri.p1 = v[1], tri.p2 = v[2];
    const Vec3 c = glm::cross(v[1] - v[0], v[2] - v[0]);
    tri.area = 0.5f * glm::length(c);
    tri.n = scene.surfaceAt(t, 1.0f / 3, 1.0f / 3).ng;
    const Material& m = scene.materials()[scene.triangleMaterial(t)];
    tri.albedo = static_cast<const Lambertian&>(*m.bsdf).albedo().factor();
    if (const AreaLight* light = scene.triangleLight(t)) {
      tri.Le = light->meanRadiance();
      tri.light = lightIndex.at(light);
      lightTriangle[size_t(tri.light)] = t;
    }
  }
  device = rtcNewDevice(nullptr);
  rtc = rtcNewScene(device);
  rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);  // as Scene builds its own
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * size_t(count)));
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, count));
  for (uint32_t t = 0; t < count; ++t) {
    const Vec3* p[3] = {&triangles[t].p0, &triangles[t].p1, &triangles[t].p2};
    for (int k = 0; k < 3; ++k) {
      vertices[9 * t + 3 * k] = p[k]->x, vertices[9 * t + 3 * k + 1] = p[k]->y, vertices[9 * t + 3 * k + 2] = p[k]->z;
      indices[3 * t + k] = 3 * t + k;
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(rtc, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(rtc);
}

LeastPathScene::~LeastPathScene() {
  rtcReleaseScene(rtc);
  rtcReleaseDevice(device);
}

LeastPathResult leastPathLoop(const Scene& scene, int width, int height, int spp, int maxDepth, int threads, uint64_t seed) {
  const LeastPathScene least(scene);
  const std::vector<LeastTriangle>& triangles = least.triangles;
  const std::vector<uint32_t>& lightTriangle = least.lightTriangle;
  const RTCScene rtc = least.rtc;
  const AliasTable& lightPick = scene.lightDistribution();
  const float eps = scene.epsilon();
  LeastPathResult result;
  result.image.assign(size_t(width) * height, Vec3(0.0f));
  LeastRowCounts rows(height);

  const auto t0 = std::chrono::steady_clock::now();
  parallelFor(size_t(height), threads, [&](size_t y, int) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    uint64_t rays = 0, shadowRays = 0;
    double sum = 0, sumSquares = 0;
    for (int x = 0; x < width; ++x) {
      const uint64_t pixel = uint64_t(y) * width + x;
      glm::dvec3 pixelSum(0.0);
      for (int s = 0; s < spp; ++s) {
        Rng rng = Rng::keyed(seed, pixel, uint64_t(s));
        const float jx = rng.uniform(), jy = rng.uniform();
        Ray ray = scene.cameraRay(x + jx, float(y) + jy, width, height);
        Vec3 L(0.0f), beta(1.0f);
        bool cameraRay = true;  // emission seen directly gets full weight
        float bsdfPdf = 0;
        for (int depth = 0;; ++depth) {
          RTCRayHit rh;
          rh.ray.org_x = ray.o.x, rh.ray.org_y = ray.o.y, rh.ray.org_z = ray.o.z;
          rh.ray.dir_x = ray.d.x, rh.ray.dir_y = ray.d.y, rh.ray.dir_z = ray.d.z;
          rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.time = 0, rh.ray.mask = 0xFFFFFFFFu, rh.ray.id = 0, rh.ray.flags = 0;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(rtc, &context, &rh);
          ++rays;
          if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
          const LeastTriangle& tri = triangles[rh.hit.primID];
          const Vec3 p = ray.o + rh.ray.tfar * ray.d;
          const float cosFront = -glm::dot(tri.n, ray.d);  // > 0: the ray meets the front face

          // Emission found by BSDF sampling, weighted against next-event estimation's density
          // for the same point: p_light = pmf · r² / (A |cos θ_light|).
          if (tri.light >= 0 && cosFront > 0) {
            float w = 1.0f;
            if (!cameraRay) {
              const float lightPdf = lightPick.pmf(size_t(tri.light)) * rh.ray.tfar * rh.ray.tfar / (tri.area * cosFront);
              w = powerHeuristic(bsdfPdf, lightPdf);
            }
            L += beta * tri.Le * w;
          }
          if (depth >= maxDepth) break;
          const Vec3 n = cosFront > 0 ? tri.n : -tri.n;  // the side the ray arrived on
          const Vec3 f = tri.albedo * kInvPi;

          // Next-event estimation: a light by power, a point uniform on it, one shadow ray.
          {
            float pmf;
            const size_t index = lightPick.sample(rng.uniform(), &pmf);
            const LeastTriangle& light = triangles[lightTriangle[index]];
            const float v = rng.uniform(), u = rng.uniform();  // the order Sampler::get2D draws them
            const Vec2 b = sampleUniformTriangle(Vec2(u, v));
            const Vec3 target = b.x * light.p0 + b.y * light.p1 + (1 - b.x - b.y) * light.p2;
            const Vec3 toLight = target - p;
            const float r2 = glm::dot(toLight, toLight), distance = std::sqrt(r2);
            const Vec3 wi = toLight / distance;
            const float cosSurface = glm::dot(n, wi), cosLight = -glm::dot(light.n, wi);
            if (cosSurface > 0 && cosLight > 0) {
              // From the offset origin to the light point, stopping one epsilon short of it.
              const Vec3 origin = p + eps * n;
              const Vec3 d = target - origin;
              const float length = glm::length(d);
              RTCRay shadow;
              shadow.org_x = origin.x, shadow.org_y = origin.y, shadow.org_z = origin.z;
              shadow.dir_x = d.x / length, shadow.dir_y = d.y / length, shadow.dir_z = d.z / length;
              shadow.tnear = 0, shadow.tfar = length - eps, shadow.time = 0, shadow.mask = 0xFFFFFFFFu, shadow.id = 0, shadow.flags = 0;
              rtcOccluded1(rtc, &context, &shadow);
              ++shadowRays;
              if (shadow.tfar >= 0) {  // unoccluded (Embree sets tfar to −inf on a hit)
                const float lightPdf = pmf * r2 / (light.area * cosLight);
                const float w = powerHeuristic(lightPdf, cosSurface * kInvPi);
                L += beta * f * light.Le * (cosSurface * w / lightPdf);
              }
            }
          }

          // BSDF sampling, cosine-weighted: f cos θ / p = ρ.
          const float v = rng.uniform(), u = rng.uniform();
          const Vec3 local = sampleCosineHemisphere(Vec2(u, v));
          const Frame frame(n);
          const Vec3 wi = frame.toWorld(local);
          bsdfPdf = local.z * kInvPi;
          if (bsdfPdf <= 0) break;
          beta *= tri.albedo;
          cameraRay = false;
          ray = Ray{p + eps * n, wi, 0.0f, INFINITY};

          if (depth >= roulette::kFirstDepth) {  // Russian roulette by throughput, as the path tracer's
            const float q = roulette::throughput(maxComponent(beta));
            if (!roulette::survives(q, [&] { return rng.uniform(); })) break;
            beta /= q;
          }
        }
        pixelSum += glm::dvec3(L);
        const double m = (double(L.x) + L.y + L.z) / 3;
        sum += m, sumSquares += m * m;
      }
      result.image[pixel] = Vec3(pixelSum / double(spp));
    }
    rows.rays[y] = rays, rows.shadowRays[y] = shadowRays;
    rows.sum[y] = sum, rows.sumSquares[y] = sumSquares;
  });
  result.seconds = secondsSince(t0);
  rows.total(double(width) * height * spp, &result);
  return result;
}

}  // namespace pl
