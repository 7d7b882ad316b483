// Renders a scene with an integrator: samples are taken one pass (one sample per pixel) at a
// time, so --time can stop at a sample boundary and every pixel has the same sample count.
#pragma once
#include <chrono>
#include <functional>
#include <string>

#include "integrators/integrator.h"
#include "render/image.h"

namespace pl {

struct RenderStats;

// A render's time: wall time since construction, minus the time spent in excluded work
// (checkpoints write images; that is neither part of the measured time nor of the budget).
class RenderClock {
 public:
  double elapsed() const { return since(start_) - paused_; }
  template <typename Fn>
  void excluding(Fn&& fn) {
    auto t0 = std::chrono::steady_clock::now();
    fn();
    paused_ += since(t0);
  }

 private:
  static double since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double paused_ = 0.0;
};

// Checkpoints fall after samples (or passes) 1, 2, 4, 8, ... and after the last.
inline bool isCheckpoint(int n) { return n > 0 && (n & (n - 1)) == 0; }

struct RenderOptions {
  int width = 0, height = 0;  // 0: derived (see resolveResolution)
  int spp = 16;
  double timeLimit = 0.0;  // seconds; 0 = none. Stops at the first pass boundary after it.
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
  int spp = 0;  // samples per pixel actually taken
  double seconds = 0.0;
  uint64_t nonFiniteSamples = 0;  // discarded (counted as zero)
  bool interrupted = false;       // stopped early by SIGINT/SIGTERM (see core/interrupt.h)
};

// Width and height from the options and the camera: --width alone keeps the camera's aspect
// ratio (square when the file gives none); neither gives 512 wide.
void resolveResolution(const Camera& camera, RenderOptions& options);

// Pixel value = average radiance over the pixel's area (box filter): sample s of pixel (x, y)
// uses the random stream keyed by (seed, pixel index, s), never by thread.
// Calls integrator.preprocess() first (its time is part of the render time).
ImageRGB render(const Scene& scene, Integrator& integrator, RenderOptions options, RenderStats* stats);

}  // namespace pl
