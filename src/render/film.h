// A film that takes splats: contributions that land on arbitrary pixels (light tracing, and the
// light-side strategies of bidirectional methods), from any thread.
//
// Each fixed chunk of paths writes its splats into a buffer of its own; the buffers are added to
// the film in chunk order. The sums are then the same, bit for bit, whatever the thread count
// (as the photon tracer's chunk buffers make its maps).
#pragma once
#include <cstdint>
#include <vector>

#include "core/common.h"
#include "render/image.h"

namespace pl {

struct Splat {
  uint32_t pixel;
  float r, g, b;
};

// The splats of one chunk of paths.
class SplatBuffer {
 public:
  // At film position (x, y) in pixels; a non-finite value is counted and dropped.
  void add(const Vec2& raster, int width, const Spectrum& v) {
    if (!isFinite(v)) {
      ++nonFinite_;
      return;
    }
    if (isBlack(v)) return;
    splats_.push_back({uint32_t(int(raster.y) * width + int(raster.x)), v.r, v.g, v.b});
  }
  void clear() { splats_.clear(), nonFinite_ = 0; }
  const std::vector<Splat>& splats() const { return splats_; }
  uint64_t nonFinite() const { return nonFinite_; }

 private:
  std::vector<Splat> splats_;
  uint64_t nonFinite_ = 0;
};

class SplatFilm {
 public:
  SplatFilm(int width, int height) : width_(width), height_(height), sum_(size_t(width) * height * 3, 0.0) {}
  // Adds buffers in the order given (chunk order), in double precision.
  void add(const std::vector<SplatBuffer>& buffers) {
    for (const SplatBuffer& b : buffers) {
      for (const Splat& s : b.splats()) {
        double* p = &sum_[size_t(s.pixel) * 3];
        p[0] += s.r, p[1] += s.g, p[2] += s.b;
      }
      nonFinite_ += b.nonFinite();
    }
  }
  void add(const SplatFilm& other) {
    for (size_t i = 0; i < sum_.size(); ++i) sum_[i] += other.sum_[i];
    nonFinite_ += other.nonFinite_;
  }
  void clear() {
    std::fill(sum_.begin(), sum_.end(), 0.0);
    nonFinite_ = 0;
  }
  // The sums times `scale`.
  ImageRGB image(double scale) const {
    ImageRGB img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i) img.data[i] = float(sum_[i] * scale);
    return img;
  }
  uint64_t nonFinite() const { return nonFinite_; }

 private:
  int width_, height_;
  std::vector<double> sum_;
  uint64_t nonFinite_ = 0;
};

}  // namespace pl
