// The least path loop in 16 SIMD lanes (bench/least_path_loop.h): what a vectorised wavefront
// design buys a path tracer, measured on the same estimator as the one-path-at-a-time loop.
// The kernel is least_path_loop_simd_kernel.h, compiled once per instruction set.
//
// A row's paths for one sample index (one per pixel, as the render loop's passes hold them)
// advance bounce by bounce. Each bounce takes the live paths 16 at a time: their rays go to
// Embree as one packet (rtcIntersect16), the hit's shading, the light sample and the BSDF
// sample are computed for all 16 lanes at once in vector registers (GCC's vector extensions;
// Mitsuba 3's LLVM backend runs its kernels the same way), the 16 shadow rays go as one
// rtcOccluded16, and the finished paths are then squeezed out (stream compaction) so that the
// next bounce's packets are full again.
//
// Every path draws from the scalar loop's stream, Rng::keyed(seed, pixel, sample), in the
// scalar loop's order, and Embree's packet queries return the one-ray queries' hits bit for bit
// (docs/pages/explanation/performance.md). So the two loops compute the same paths with the same random numbers;
// they differ only by the rounding of a few operations (1/√ once instead of a division per
// component), which can flip a rare comparison. The test compares them pixel by pixel.
//
// Why 16 lanes and not a scalar wavefront: measured, a wavefront of one path per iteration
// (queues, the same kernels in scalar code) was 0.87–0.96× the one-path loop, and the same 16-lane
// loop left to GCC's auto-vectoriser (which vectorised none of the shading loops) 0.97–1.09×.
// The lanes pay only when the arithmetic itself is written for them.
#include <chrono>
#include <cmath>
#include <cstring>

#include "bench/least_path_loop.h"
#include "bench/least_path_scene.h"
#include "core/lanes_isa.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "render/integrator.h"

// The kernel (least_path_loop_simd_kernel.h), compiled for each instruction set: core/lanes.h.
#define PL_LANES_KERNEL "bench/least_path_loop_simd_kernel.h"
#include "core/lanes_copies.h"
#undef PL_LANES_KERNEL

namespace pl {

LeastPathResult leastPathLoopSimd(const Scene& scene, int width, int height, int spp, int maxDepth, int threads, uint64_t seed) {
  const LeastPathScene least(scene);
  LeastPathResult result;
  result.image.assign(size_t(width) * height, Vec3(0.0f));
  LeastRowCounts rows(height);
  const auto t0 = std::chrono::steady_clock::now();
  switch (lanes::bestIsa()) {
    case lanes::Isa::Avx512: least_simd::avx512::traceRows(scene, least, width, height, spp, maxDepth, threads, seed, &result, &rows); break;
    case lanes::Isa::Baseline: least_simd::baseline::traceRows(scene, least, width, height, spp, maxDepth, threads, seed, &result, &rows); break;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rows.total(double(width) * height * spp, &result);
  return result;
}

}  // namespace pl
