// Error metrics of an image x against a reference r, over all pixels and channels (n values):
//   rmse   = sqrt( Σ (x − r)² / n )
//   relmse = Σ (x − r)² / (r² + 0.01) / n        (relative MSE; 0.01 keeps black pixels finite)
//   mae    = Σ |x − r| / n
//   meanRatio = mean(x) / mean(r)                  (1 = no overall brightening or darkening)
#pragma once
#include "image/image.h"

namespace pl {

struct ErrorMetrics {
  double rmse = 0, relmse = 0, mae = 0, meanRatio = 0;
};

ErrorMetrics compareImages(const ImageRGB& image, const ImageRGB& reference);

// The relMSE that the mean x = (a + b)/2 of two independent unbiased renders a, b of equal
// variance has, without a reference: E[(x − r)²] = Var x = E[(a − b)²]/4 per value, divided by
// x² + 0.01 in place of r² + 0.01 (photonlab bench: the error after a given time).
double relMSEFromHalves(const ImageRGB& a, const ImageRGB& b);

}  // namespace pl
