// One render session: what every render loop shares, whatever its unit of work (a sample per
// pixel, a photon pass, a light-path iteration). It starts the time budget (preprocessing counts
// towards the render time), resolves the resolution and the thread count, checks that the film
// fits in memory, and runs the units of the render or of its slice (--sample-range) with the
// progress bar, the checkpoints and the stop on the budget or an interrupt. The loops that use it
// keep only their algorithm: renderPixels (render/renderer.cpp, with the training hook of
// integrators that learn between iterations), LightPathIntegrator (render/light_loop.cpp), the
// progressive passes (integrators/progressive.h) and the bidirectional iterations
// (integrators/bidirectional.cpp).
#pragma once
#include <functional>
#include <string>

#include "core/budget.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "render/checkpoints.h"
#include "render/render_options.h"
#include "scene/scene.h"

namespace pl {

class RenderSession {
 public:
  // `bytesPerPixel`: what the loop allocates per pixel, checked against the memory available;
  // `film` names it in the message ("image", "splat film").
  RenderSession(const Scene& scene, const RenderOptions& options, uint64_t bytesPerPixel, const char* film)
      : budget(options.timeLimit, options.clock), options_(options) {
    resolveResolution(scene.camera(), options_);
    width = options_.width, height = options_.height;
    pixels = size_t(width) * height;
    threads = resolveThreads(options_.threads);
    checkMemory(mulSaturate(pixels, bytesPerPixel), std::to_string(width) + "x" + std::to_string(height) + " " + film);
  }
  RenderSession(const RenderSession&) = delete;

  // The options with the resolution resolved.
  const RenderOptions& options() const { return options_; }
  // The units this render runs when the whole render has `total` (INT32_MAX: until the budget
  // ends): 0 … total − 1, or a slice's first, first + step, … below its end.
  UnitRange units(int total) const { return unitRange(options_, total); }

  // What every loop reports the same way: the time, why it stopped, whether this is the end.
  RenderInfo info(bool last) const {
    RenderInfo st;
    st.seconds = budget.elapsed();
    st.interrupted = interruptRequested();
    st.timeUp = budget.timeUp();
    st.last = last;
    return st;
  }

  // Runs unit(u) for u in `range` until the range ends, the budget expires or an interrupt
  // arrives. unit(u) returns false when the budget cut it short and it is dropped whole (a
  // light-path iteration: a part of one would brighten some regions only); then the loop ends.
  // After each completed unit: the progress bar, and a checkpoint after units 1, 2, 4, ... and
  // the last (info(last) the RenderInfo so far, image() the estimate). Returns the units done.
  template <typename UnitFn, typename InfoFn, typename ImageFn>
  int run(const UnitRange& range, UnitFn&& unit, InfoFn&& info, ImageFn&& image) {
    Progress progress(options_, range.count());
    Checkpoints checkpoints(options_, budget);
    int done = 0;
    for (int u = range.first; u < range.end && !budget.expired(); u += range.step) {
      if (!unit(u)) break;
      ++done;
      progress.update(done, budget.elapsed(), progressNote ? progressNote() : std::string());
      const bool last = int64_t(u) + range.step >= range.end || budget.expired();
      checkpoints.after(done, last, info, image);
      if (last) break;
    }
    // E.g. the budget ended in preprocessing: the render's last, black, image all the same.
    checkpoints.finish(info, image);
    return done;
  }

  Budget budget;  // polled by the loops between small units of work (a pixel, a chunk of paths)
  std::function<std::string()> progressNote;  // set by a loop that has more to say on the progress bar
  int width = 0, height = 0, threads = 1;
  size_t pixels = 0;

 private:
  RenderOptions options_;
};

}  // namespace pl
