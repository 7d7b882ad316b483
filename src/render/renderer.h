// Renders a scene with an integrator: samples are taken one pass (one sample per pixel) at a
// time, so --time can stop at a sample boundary and every pixel has the same sample count.
#pragma once
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "integrators/integrator.h"
#include "render/image.h"

namespace pl {

struct RenderStats;

// Checkpoints fall after samples (or passes) 1, 2, 4, 8, ... and after the last.
inline bool isCheckpoint(int n) { return n > 0 && (n & (n - 1)) == 0; }

struct RenderOptions {
  int width = 0, height = 0;  // 0: derived (see resolveResolution)
  int spp = 16;
  // Seconds; 0 = none. The render stops when it is spent, wherever it is (see core/budget.h):
  // within a pixel's sample of it, or a chunk of photon paths, or a slice of the kd-tree build.
  double timeLimit = 0.0;
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  bool progress = false;
  // --aov nan: instead of radiance, each pixel holds the fraction of its samples that were
  // non-finite (NaN or ±Inf) and discarded; 0 everywhere in a healthy render.
  bool nanAov = false;
  // --spectral: paths carry wavelengths and the film integrates against the CIE 1931 curves
  // (spectral/spectral.h). The integrator must have been made with spectral options too.
  bool spectral = false;
  // Called with the estimate so far after 1, 2, 4, 8, ... samples per pixel and after the last
  // one; the time it takes is not counted in RenderStats::seconds nor against timeLimit.
  std::function<void(const ImageRGB&, const RenderStats&)> checkpoint;
};

struct RenderStats {
  int spp = 0;           // samples every pixel has
  double meanSpp = 0.0;  // samples per pixel on average: spp + the share of pixels a budget-cut pass reached
  double seconds = 0.0;  // the time actually spent (preprocessing included, checkpoints excluded)
  uint64_t nonFiniteSamples = 0;  // discarded (counted as zero)
  bool interrupted = false;       // stopped early by SIGINT/SIGTERM (see core/interrupt.h)
  bool timeUp = false;            // stopped because the time budget was spent
  bool last = false;              // the render's final image
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

// Pixel value = average radiance over the pixel's area (box filter): sample s of pixel (x, y)
// uses the random stream keyed by (seed, pixel index, s), never by thread.
// Calls integrator.preprocess() first (its time is part of the render time). Checks the time
// limit and interrupts per pixel; a pass they cut short leaves some pixels with one sample more.
ImageRGB render(const Scene& scene, Integrator& integrator, RenderOptions options, RenderStats* stats);

}  // namespace pl
