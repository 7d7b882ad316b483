// The film of an integrator that learns between iterations (render/integrator.h, TrainingHook):
// the sums of the iteration under way, and the image as the iterations so far combined by
// inverse variance. Each iteration samples with what was learned before it, so each is an
// unbiased image on its own; a poorly trained one has more variance and counts less (Müller,
// "Practical Path Guiding" in Production, 2019, §3: inverse-variance weighting of iterations).
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/common.h"
#include "image/image.h"
#include "render/integrator.h"

namespace pl {

class IterationFilm {
 public:
  // What the film holds per pixel, for the memory check.
  static constexpr uint64_t kBytesPerPixel = 6 * sizeof(double) + 4 * sizeof(double) + sizeof(uint32_t) + 3 * sizeof(float);

  IterationFilm(int width, int height) : W_(width), H_(height), pixels_(size_t(width) * height),
                                         numerator_(3 * pixels_, 0.0), denominator_(pixels_, 0.0) {}

  // A new iteration; with `replaces`, its image takes the place of the iterations' before it.
  void begin(bool replaces) {
    current_ = std::make_unique<Sums>(pixels_);
    replaces_ = replaces;
  }
  bool running() const { return current_ != nullptr; }

  // A sample of the iteration under way: counted always, added when finite (a non-finite one is
  // discarded, a zero sample). Each pixel is added to by one thread per pass, in sample order.
  void count(size_t pixel) { ++current_->count[pixel]; }
  void add(size_t pixel, const Spectrum& L) {
    Sums& it = *current_;
    for (int c = 0; c < 3; ++c) it.sum[3 * pixel + c] += L[c];
    const double a = average(L);
    it.a[pixel] += a, it.a2[pixel] += a * a;
  }
  // The pixel's value from the iterations before this one (channel mean; 0 before the first ends).
  float pixelValue(size_t i) const {
    return denominator_[i] > 0
               ? float((numerator_[3 * i] + numerator_[3 * i + 1] + numerator_[3 * i + 2]) / (3 * denominator_[i]))
               : 0.0f;
  }

  // Ends the iteration under way: it joins the image; the report's variance figures are its.
  IterationReport end() {
    const Sums& it = *current_;
    IterationReport r;
    uint32_t least = UINT32_MAX;
    for (uint32_t n : it.count) least = std::min(least, n);
    r.least = int(least);
    r.variance = (sampleVariance(it, 0) + sampleVariance(it, 1)) / 2;
    addIteration(it, numerator_, denominator_);
    r.relativeVariance = relativeVariance(it);
    current_.reset();
    return r;
  }

  // The image: the iterations ended, and the one under way as it stands.
  ImageRGB image() const {
    std::vector<double> num = numerator_, den = denominator_;
    if (current_) addIteration(*current_, num, den);
    ImageRGB image(W_, H_);
    for (size_t i = 0; i < pixels_; ++i)
      if (den[i] > 0)
        for (int c = 0; c < 3; ++c) image.data[3 * i + c] = float(num[3 * i + c] / den[i]);
    return image;
  }

 private:
  // One iteration's per-pixel sums: Σ L per channel, and Σ a and Σ a² of a = mean(L over
  // channels) for its variance.
  struct Sums {
    std::vector<double> sum, a, a2;
    std::vector<uint32_t> count;
    explicit Sums(size_t pixels) : sum(3 * pixels, 0.0), a(pixels, 0.0), a2(pixels, 0.0), count(pixels, 0) {}
  };

  // The variance of one sample of the iteration, pooled over the pixels of one colour of a
  // checkerboard ((x + y) mod 2 = parity): Σ (Σa² − (Σa)²/n) / Σ (n − 1). With one sample per
  // pixel there is no within-pixel spread; then differences of diagonal neighbours (the same
  // colour) stand in, σ² ≈ mean((a_{x,y} − a_{x+1,y+1})²)/2, an overestimate wherever the image
  // has edges (it can only lower that iteration's weight).
  double sampleVariance(const Sums& it, int parity) const {
    double ss = 0, dof = 0;
    for (int y = 0; y < H_; ++y)
      for (int x = (y + parity) & 1; x < W_; x += 2) {
        size_t i = size_t(y) * W_ + x;
        if (it.count[i] < 2) continue;
        ss += it.a2[i] - it.a[i] * it.a[i] / it.count[i];
        dof += it.count[i] - 1;
      }
    if (dof > 0) return std::max(0.0, ss / dof);
    double d2 = 0;
    size_t pairs = 0;
    for (int y = 0; y + 1 < H_; ++y)
      for (int x = (y + parity) & 1; x + 1 < W_; x += 2) {
        size_t i = size_t(y) * W_ + x, j = i + W_ + 1;
        if (!it.count[i] || !it.count[j]) continue;
        double d = it.a[i] / it.count[i] - it.a[j] / it.count[j];
        d2 += d * d, ++pairs;
      }
    return pairs ? d2 / pairs / 2 : 0.0;
  }

  // Σ_k w_k·(pixel mean of iteration k) and Σ_k w_k per pixel, w_k = n_k(pixel)/σ²_k: the
  // variance of a pixel's mean in iteration k is σ²_k/n_k. σ²_k is estimated on the other colour
  // of the checkerboard than the pixel's: weights estimated from the pixel's own samples would be
  // correlated with its values (an iteration that drew a firefly has a higher σ² and less
  // weight), which biases the mean; from other pixels' samples, the weights are independent of
  // the values they weigh, and the combination is unbiased. Exact images (no noise) are weighted
  // by their sample counts alone.
  void addIteration(const Sums& it, std::vector<double>& num, std::vector<double>& den) const {
    const double v[2] = {std::max(sampleVariance(it, 1), 1e-30), std::max(sampleVariance(it, 0), 1e-30)};
    if (replaces_) std::fill(num.begin(), num.end(), 0.0), std::fill(den.begin(), den.end(), 0.0);
    for (size_t i = 0; i < pixels_; ++i) {
      if (!it.count[i]) continue;
      const int parity = int((i % size_t(W_) + i / size_t(W_)) & 1);
      const double w = it.count[i] / v[parity];  // the other colour's variance
      for (int c = 0; c < 3; ++c) num[3 * i + c] += w * (it.sum[3 * i + c] / it.count[i]);
      den[i] += w;
    }
  }

  // The relative variance of one sample of the iteration, as relMSE weighs errors: each pixel's
  // sample variance (of the channel mean a) over m² + 0.01, m the pixel's value in the image,
  // averaged over the pixels with two samples or more (0 if none has).
  double relativeVariance(const Sums& it) const {
    double sum = 0;
    size_t pixels = 0;
    for (size_t i = 0; i < it.count.size(); ++i) {
      const uint32_t n = it.count[i];
      if (n < 2 || !(denominator_[i] > 0)) continue;
      const double m = (numerator_[3 * i] + numerator_[3 * i + 1] + numerator_[3 * i + 2]) / (3 * denominator_[i]);
      sum += std::max(0.0, it.a2[i] - it.a[i] * it.a[i] / n) / (n - 1) / (m * m + 0.01);
      ++pixels;
    }
    return pixels ? sum / double(pixels) : 0.0;
  }

  int W_, H_;
  size_t pixels_;
  std::vector<double> numerator_, denominator_;
  std::unique_ptr<Sums> current_;
  bool replaces_ = false;
};

}  // namespace pl
