// What every render takes (image size, seed, threads, budget, spectral film, checkpoints) and
// what it reports, whatever the integrator.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/exact_sum.h"

#include "lights/environment_light.h"
#include "image/image.h"
#include "scene/camera.h"

namespace pl {

struct RenderInfo;
class Clock;

// Checkpoints fall after samples (or passes) 1, 2, 4, 8, ... and after the last.
inline bool isCheckpoint(int n) { return n > 0 && (n & (n - 1)) == 0; }

struct RenderOptions {
  int width = 0, height = 0;  // 0: derived (see resolveResolution)
  // Which of the scene file's cameras renders (GltfLoadOptions::camera); −1: the first, or the
  // automatic view of a file without one. Read when the scene is loaded.
  int camera = -1;
  // A view from the command line instead (GltfLoadOptions::view); read when the scene is loaded.
  CameraView view;
  // The sky (--env, an experiment's env): replaces the file's; read when the scene is loaded.
  EnvironmentSpec environment;
  // --units radiometric|photometric (GltfLoadOptions::units); empty: as the file says.
  std::string units;
  // Samples per pixel of the per-pixel and light-side loops (0: until the time budget ends);
  // pass-based integrators count passes in their own parameters.
  int spp = 16;
  // Seconds; 0 = none. The render stops when it is spent, wherever it is (see core/budget.h):
  // within a pixel's sample of it, or a chunk of photon paths, or a slice of the kd-tree build.
  double timeLimit = 0.0;
  // Where the budget reads the time (core/budget.h): the steady clock when null; tests inject one.
  Clock* clock = nullptr;
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  bool progress = false;
  // --aov nan: instead of radiance, each pixel holds the fraction of its samples that were
  // non-finite (NaN or ±Inf) and discarded; 0 everywhere in a healthy render.
  bool nanAov = false;
  // --spectral: paths carry wavelengths and the film integrates against the CIE 1931 curves
  // (spectral/spectral.h).
  bool spectral = false;
  // Called with the estimate so far after 1, 2, 4, 8, ... samples (or passes) per pixel and
  // after the last one; the time it takes is not counted in RenderInfo::seconds nor against
  // timeLimit.
  std::function<void(const ImageRGB&, const RenderInfo&)> checkpoint;
  // --sample-range / --pass-range A:B[:K]: only samples (or passes) A, A+K, A+2K, ... below B
  // of the full render, each keyed exactly as the full render keys it; their exact sums come
  // back in RenderInfo::slice for `photonlab merge`. 0:0 is the whole render. Interleaved
  // slices (K > 1) share out PPPM's passes evenly: early passes, with larger radii, cost more.
  int rangeBegin = 0, rangeEnd = 0, rangeStep = 1;
  bool sliced() const { return rangeEnd > 0; }
};

// A slice's exact per-pixel sums (core/exact_sum.h) and sample counts: what `photonlab merge`
// adds up. Summing slices in any grouping gives the bits the whole render has.
struct RenderSlice {
  int width = 0, height = 0;
  int begin = 0, end = 0, step = 1;   // the samples or passes it holds: begin, begin + step, ... < end
  std::vector<ExactSum> sums;         // width·height·3: camera-side samples, each pixel's own
  std::vector<ExactSum> splats;       // width·height·3: light-side splats (light, bdpt, ...), or empty
  std::vector<uint32_t> counts;       // width·height: samples, or iterations for splats
  // The image, as the integrator forms it: sums/count, splats·(1/n), or both added.
  ImageRGB mean() const;              // render/renderer.cpp
};

// The samples (or iterations, or 0-based passes) a render runs: all of [0, total), or its slice.
struct UnitRange {
  int first, end, step;
  // In 64 bits: an unlimited render (a time budget alone) ends at INT32_MAX.
  int count() const { return int((int64_t(end) - first + step - 1) / step); }
};
inline UnitRange unitRange(const RenderOptions& o, int total) {
  return o.sliced() ? UnitRange{o.rangeBegin, o.rangeEnd, o.rangeStep} : UnitRange{0, total, 1};
}
// A sliced render's result for RenderInfo::slice: its range from `o`, and its sums.
inline std::shared_ptr<RenderSlice> makeSlice(const RenderOptions& o, int width, int height, std::vector<ExactSum> sums,
                                              std::vector<ExactSum> splats, std::vector<uint32_t> counts) {
  auto slice = std::make_shared<RenderSlice>();
  slice->width = width, slice->height = height;
  slice->begin = o.rangeBegin, slice->end = o.rangeEnd, slice->step = o.rangeStep;
  slice->sums = std::move(sums), slice->splats = std::move(splats), slice->counts = std::move(counts);
  return slice;
}

// A pixel's value from its exact sum and its sample count: the one division every render (and
// every merge) makes, so that they agree bit for bit.
inline float pixelMean(const ExactSum& sum, uint32_t count) { return float(sum.value() / count); }
// A splatted pixel's value: its sum times 1/iterations (light-side integrators).
inline float splatValue(const ExactSum& sum, double scale) { return float(sum.value() * scale); }

struct RenderInfo {
  int spp = 0;             // samples every pixel has (per-pixel and light-side integrators)
  int passes = 0;          // passes every pixel has (pass-based integrators)
  double meanWork = 0.0;   // spp or passes per pixel on average: more than spp/passes when the
                           // budget cut the last one short, after it reached some pixels
  uint64_t photons = 0;    // photon (or light) paths emitted so far
  double seconds = 0.0;    // the time actually spent (preprocessing included, checkpoints excluded)
  double meanRadius = 0.0; // mean gather radius (photon-mapping integrators), 0 otherwise
  double visibleFraction = -1.0;  // of the usable photons stored, the fraction a gather found; −1: not measured
  double visiblePaths = -1.0;     // adaptive photon tracing: the uniform paths' visible fraction V̂_c; −1: not used
  uint64_t nonFiniteSamples = 0;  // discarded (counted as zero)
  bool interrupted = false;       // stopped early by SIGINT/SIGTERM (see core/interrupt.h)
  bool timeUp = false;            // stopped because the time budget was spent
  bool last = false;              // the render's final image
  std::shared_ptr<const RenderSlice> slice;  // a sliced render's sums (RenderOptions::sliced)
};

// Samples (or passes) per pixel after a render the budget may have cut mid-pass: what every
// pixel has, and the mean.
struct PixelCounts {
  int all = 0;
  double mean = 0.0;
};
inline PixelCounts summarizeCounts(const std::vector<uint32_t>& counts) {
  if (counts.empty()) return {};
  uint32_t lo = UINT32_MAX;
  uint64_t total = 0;
  for (uint32_t n : counts) lo = std::min(lo, n), total += n;
  return {int(lo), double(total) / counts.size()};
}

// Width and height from the options and the camera: --width alone keeps the camera's aspect
// ratio (square when the file gives none); neither gives 512 wide.
void resolveResolution(const Camera& camera, RenderOptions& options);

}  // namespace pl
