#include "io/metrics.h"

namespace pl {

ErrorMetrics compareImages(const ImageRGB& x, const ImageRGB& r) {
  if (x.width != r.width || x.height != r.height)
    throw Error("compare: image is " + std::to_string(x.width) + "x" + std::to_string(x.height) + ", reference is " +
                std::to_string(r.width) + "x" + std::to_string(r.height));
  ErrorMetrics m;
  size_t n = x.data.size();
  if (n == 0) throw Error("compare: empty images");
  double se = 0, rel = 0, ae = 0, sx = 0, sr = 0;
  for (size_t i = 0; i < n; ++i) {
    double a = x.data[i], b = r.data[i], d = a - b;
    if (!std::isfinite(a) || !std::isfinite(b)) throw Error("compare: non-finite pixel value at index " + std::to_string(i / 3));
    se += d * d;
    rel += d * d / (b * b + 0.01);
    ae += std::abs(d);
    sx += a;
    sr += b;
  }
  m.rmse = std::sqrt(se / n);
  m.relmse = rel / n;
  m.mae = ae / n;
  m.meanRatio = sr != 0 ? sx / sr : (sx == 0 ? 1.0 : INFINITY);
  return m;
}

double relMSEFromHalves(const ImageRGB& a, const ImageRGB& b) {
  if (a.width != b.width || a.height != b.height || a.data.empty())
    throw Error("relMSEFromHalves: the two images differ in size or are empty");
  double rel = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const double u = a.data[i], v = b.data[i], x = (u + v) / 2;
    rel += (u - v) * (u - v) / 4 / (x * x + 0.01);
  }
  return rel / double(a.data.size());
}

}  // namespace pl
