// Error metrics of an image x against a reference r, over all pixels and channels (n values):
//   rmse   = sqrt( Σ (x − r)² / n )
//   relmse = Σ (x − r)² / (r² + 0.01) / n        (relative MSE; 0.01 keeps black pixels finite)
//   mae    = Σ |x − r| / n
//   meanRatio = mean(x) / mean(r)                  (1 = no overall brightening or darkening)
#pragma once
#include "render/image.h"

namespace pl {

struct ErrorMetrics {
  double rmse = 0, relmse = 0, mae = 0, meanRatio = 0;
};

ErrorMetrics compareImages(const ImageRGB& image, const ImageRGB& reference);

}  // namespace pl
