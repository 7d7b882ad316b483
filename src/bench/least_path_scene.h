// What the least path loops (bench/least_path_loop.h: one path at a time, and 16 paths in
// SIMD lanes) know of a scene: one flat record per triangle and an Embree scene of their own,
// whose primID indexes the records. Built only for the scenes leastPathLoopUnsupported accepts.
#pragma once
#include <embree3/rtcore.h>

#include <vector>

#include "bench/least_path_loop.h"
#include "scene/scene.h"

namespace pl {

// All the loops need at a hit.
struct LeastTriangle {
  Vec3 p0, p1, p2;
  Vec3 n;          // unit, on the counter-clockwise side (the side an area light emits from)
  Vec3 albedo;     // ρ of its Lambertian
  Vec3 Le{0.0f};   // emitted radiance (front side only); zero where it does not emit
  float area = 0;
  int light = -1;  // its index in Scene::lights(), or -1
};

struct LeastPathScene {
  // Throws pl::Error where leastPathLoopUnsupported(scene) says why.
  explicit LeastPathScene(const Scene& scene);
  ~LeastPathScene();
  LeastPathScene(const LeastPathScene&) = delete;
  LeastPathScene& operator=(const LeastPathScene&) = delete;

  std::vector<LeastTriangle> triangles;  // by Embree primID
  std::vector<uint32_t> lightTriangle;   // light index → its triangle
  RTCDevice device = nullptr;
  RTCScene rtc = nullptr;
};

// What the loops count per row (each row its own entry, so threads need no atomics), and the
// result's totals from them.
struct LeastRowCounts {
  explicit LeastRowCounts(int height) : rays(height, 0), shadowRays(height, 0), sum(height, 0.0), sumSquares(height, 0.0) {}
  std::vector<uint64_t> rays, shadowRays;
  std::vector<double> sum, sumSquares;  // of each sample's mean channel
  // Rays and the variance of one sample's mean channel over `samples` samples, into result.
  void total(double samples, LeastPathResult* result) const {
    double all = 0, squares = 0;
    for (size_t y = 0; y < rays.size(); ++y) {
      result->closestRays += rays[y], result->shadowRays += shadowRays[y];
      all += sum[y], squares += sumSquares[y];
    }
    result->sampleVariance = samples > 1 ? (squares - all * all / samples) / (samples - 1) : 0.0;
  }
};

}  // namespace pl
