// The checkpoints every render loop hands out through RenderOptions::checkpoint: the estimate
// after units 1, 2, 4, 8, ... (samples, passes or light-path iterations) and after the last. The
// time they take is excluded from the budget. When the budget ends before the first unit (in
// preprocessing), finish() still hands over the render's last, black, image.
#pragma once
#include "core/budget.h"
#include "render/render_options.h"

namespace pl {

class Checkpoints {
 public:
  Checkpoints(const RenderOptions& options, Budget& budget) : options_(options), budget_(budget) {}

  // After unit `done`: `info(last)` returns the RenderInfo so far, `image()` the estimate.
  template <typename InfoFn, typename ImageFn>
  void after(int done, bool last, InfoFn&& info, ImageFn&& image) {
    if (!options_.checkpoint || !(isCheckpoint(done) || last)) return;
    budget_.excluding([&] {
      RenderInfo st = info(last);
      options_.checkpoint(image(), st);
    });
    handedLast_ = last;
  }
  // When the loop has ended: the last image, unless after() has handed it over already.
  template <typename InfoFn, typename ImageFn>
  void finish(InfoFn&& info, ImageFn&& image) {
    if (!options_.checkpoint || handedLast_) return;
    budget_.excluding([&] {
      RenderInfo st = info(true);
      options_.checkpoint(image(), st);
    });
  }

 private:
  const RenderOptions& options_;
  Budget& budget_;
  bool handedLast_ = false;
};

}  // namespace pl
