// What every render loop reports as it goes, in units of work (samples, passes or light-path
// iterations): the progress bar, and the checkpoints handed out through RenderOptions::checkpoint.
#pragma once
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <string>

#include "core/budget.h"
#include "render/render_options.h"

namespace pl {

// How many units a loop runs: `count` (spp or passes) when given, unlimited with a time budget
// alone, else one.
inline int unitTarget(int count, double timeLimit) { return count > 0 ? count : (timeLimit > 0 ? INT_MAX : 1); }

// A progress bar with ETA on stderr when it is a terminal and options.progress is set: the share
// of the units done, or of the time budget when the units are unlimited. At most 10 updates/s.
class Progress {
 public:
  Progress(const RenderOptions& options, int target)
      : enabled_(options.progress && isatty(STDERR_FILENO)), target_(target), timeLimit_(options.timeLimit) {}
  // `note`: what the loop adds after the ETA (e.g. the photons' visibility).
  void update(int done, double elapsed, const std::string& note = "") {
    const double fraction = target_ < INT_MAX ? double(done) / target_ : std::min(1.0, elapsed / timeLimit_);
    if (!enabled_ || (elapsed - last_ < 0.1 && fraction < 1)) return;
    last_ = elapsed;
    int width = 40, filled = int(fraction * width);
    double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %6.1fs  ETA %6.1fs%s", filled, "########################################",
                 width - filled, "", 100 * fraction, elapsed, eta, note.c_str());
    std::fflush(stderr);
  }
  ~Progress() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  int target_;
  double timeLimit_;
  double last_ = -1;
};

// The estimate after units 1, 2, 4, 8, ... and after the last; the time it takes is excluded
// from the budget. When the budget ends before the first unit (in preprocessing), finish() still
// hands over the render's last, black, image.

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
