// A film that takes splats: contributions that land on arbitrary pixels (light tracing, and the
// light-side strategies of bidirectional methods), from any thread.
//
// Each fixed chunk of paths writes its splats into a buffer of its own; the buffers are added to
// the film in chunk order. The sums are then the same, bit for bit, whatever the thread count
// (as the photon tracer's chunk buffers make its maps).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/common.h"
#include "core/parallel.h"
#include "image/image.h"
#include "render/render_options.h"

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
  SplatFilm(int width, int height) : width_(width), height_(height), sum_(size_t(width) * height * 3) {}
  // Adds the buffers' splats. The sums are exact (core/exact_sum.h), so neither the buffers'
  // order nor the split into threads changes a bit, and slices of a render add up to its bits.
  // With threads > 1 each thread owns a contiguous band of pixels and adds the splats that land
  // in it (every thread reads every splat; the adds, the cost, are split).
  //
  // Splats land on scattered pixels, and added as they come each one misses the cache on its
  // pixel's three exact sums (docs: Performance). So a band's splats are first grouped by
  // blocks of kBlock pixels (a counting sort: one write stream per block, few enough to stay in
  // cache), then added block by block. Exact sums make the new order change no bit.
  void add(const std::vector<SplatBuffer>& buffers, int threads = 1) {
    const size_t parts = size_t(std::max(1, threads)), pixels = size_t(width_) * size_t(height_);
    parallelFor(parts, threads, [&](size_t part, int) {
      const size_t lo = pixels * part / parts, hi = pixels * (part + 1) / parts;
      const size_t blocks = (hi - lo + kBlock - 1) / kBlock;
      std::vector<size_t> next(blocks + 1, 0);  // counts, then each block's next free slot
      for (const SplatBuffer& b : buffers)
        for (const Splat& s : b.splats())
          if (s.pixel >= lo && s.pixel < hi) ++next[(s.pixel - lo) / kBlock + 1];
      for (size_t k = 1; k <= blocks; ++k) next[k] += next[k - 1];
      const size_t n = next[blocks];
      std::unique_ptr<Splat[]> grouped(new Splat[n]);  // not zeroed: every slot is written below
      for (const SplatBuffer& b : buffers)
        for (const Splat& s : b.splats())
          if (s.pixel >= lo && s.pixel < hi) grouped[next[(s.pixel - lo) / kBlock]++] = s;
      for (size_t i = 0; i < n; ++i) {
        const Splat& s = grouped[i];
        ExactSum* p = &sum_[size_t(s.pixel) * 3];
        p[0].add(s.r), p[1].add(s.g), p[2].add(s.b);
      }
    });
    for (const SplatBuffer& b : buffers) nonFinite_ += b.nonFinite();
  }
  void add(const SplatFilm& other, int threads = 1) {
    forSums(threads, [&](size_t i) { sum_[i].add(other.sum_[i]); });
    nonFinite_ += other.nonFinite_;
  }
  void clear(int threads = 1) {
    forSums(threads, [&](size_t i) { sum_[i] = ExactSum(); });
    nonFinite_ = 0;
  }
  // The sums times `scale`.
  ImageRGB image(double scale) const {
    ImageRGB img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i) img.data[i] = splatValue(sum_[i], scale);
    return img;
  }
  uint64_t nonFinite() const { return nonFinite_; }
  const std::vector<ExactSum>& sums() const { return sum_; }

 private:
  // fn(i) for every sum, in 64 contiguous blocks over the threads.
  template <typename Fn>
  void forSums(int threads, Fn&& fn) {
    const size_t blocks = 64, n = sum_.size();
    parallelFor(blocks, threads, [&](size_t block, int) {
      for (size_t i = n * block / blocks, end = n * (block + 1) / blocks; i < end; ++i) fn(i);
    });
  }

  static constexpr size_t kBlock = 256;  // pixels: 30 KB of sums, within a core's L1 or L2

  int width_, height_;
  std::vector<ExactSum> sum_;
  uint64_t nonFinite_ = 0;
};

}  // namespace pl
