// The least path tracer: a yardstick for `photonlab bench`, not an integrator.
//
// It computes what the `path` integrator computes (next-event estimation and cosine-weighted
// BSDF sampling, combined by the power heuristic; Russian roulette q = min(1, max β) from the
// fourth bounce; the same light choice by power), one path at a time, in scalar code, with as
// little else as a path tracer can have: raw Embree calls on the world-space triangles, a flat
// array per triangle (albedo, emitted radiance, unit normal), no shading frames, textures,
// vertex colours, virtual BSDFs, spectra, media or exact film sums. So it only takes scenes
// that need none of those: Lambertian surfaces of constant colour and one-sided, untextured
// area lights.
//
// Its rate is the ceiling for a one-path-at-a-time scalar path tracer on the scene, and the
// path tracer's rate over it is what photonlab's generality costs (docs: explanation/performance.md;
// issue 20 compares the path tracer with Mitsuba 3's, whose rate this loop's is close to).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace pl {

struct LeastPathResult {
  std::vector<Vec3> image;      // per-pixel mean radiance (linear RGB), row 0 at the top
  double seconds = 0;           // the pixel loop alone (not the set-up)
  uint64_t closestRays = 0;     // rtcIntersect1 calls
  uint64_t shadowRays = 0;      // rtcOccluded1 calls
  double sampleVariance = 0;    // variance of one sample's mean channel, over every sample of the image
};

// Empty if the loop can render `scene`; otherwise why not (one line).
std::string leastPathLoopUnsupported(const Scene& scene);

// width × height pixels, spp samples each, one path per sample (depth ≤ maxDepth bounces, as
// `--max-depth`), on `threads` threads. Throws pl::Error where leastPathLoopUnsupported says why.
LeastPathResult leastPathLoop(const Scene& scene, int width, int height, int spp, int maxDepth, int threads, uint64_t seed);

// The same loop with 16 paths in SIMD lanes (least_path_loop_simd.cpp): a row's paths for one
// sample index advance bounce by bounce, their rays in Embree's 16-ray packets, their shading in
// vector registers. Each path draws the same random numbers as in leastPathLoop, so the images
// agree pixel by pixel up to rounding; the rate is what a vectorised wavefront design buys.
LeastPathResult leastPathLoopSimd(const Scene& scene, int width, int height, int spp, int maxDepth, int threads, uint64_t seed);

}  // namespace pl
