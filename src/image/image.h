// A linear RGB float image, row 0 at the top.
#pragma once
#include <vector>

#include "core/common.h"

namespace pl {

struct ImageRGB {
  int width = 0, height = 0;
  std::vector<float> data;  // width·height·3, interleaved RGB

  ImageRGB() = default;
  ImageRGB(int w, int h) : width(w), height(h), data(size_t(w) * h * 3, 0.0f) {}
  Spectrum at(int x, int y) const {
    const float* p = &data[(size_t(y) * width + x) * 3];
    return Spectrum(p[0], p[1], p[2]);
  }
  void set(int x, int y, const Spectrum& s) {
    float* p = &data[(size_t(y) * width + x) * 3];
    p[0] = s.r, p[1] = s.g, p[2] = s.b;
  }
};

}  // namespace pl
