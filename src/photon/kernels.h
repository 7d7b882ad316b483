// Density-estimation kernels on the disc of radius r around the query point, each normalised so
// that ∫_disc K dA = 1 (derivations in the comments; tested numerically). With s = d²/r²:
#pragma once
#include <string>

#include "core/common.h"

namespace pl {

enum class Kernel {
  Uniform,       // K = 1/(πr²)
  Cone,          // K = 3/(πr²) · (1 − d/r):   ∫ (1 − d/r) 2πd dd = πr²/3   (Jensen's cone filter, k = 1)
  Epanechnikov,  // K = 2/(πr²) · (1 − s):     ∫ (1 − s) 2πd dd = πr²/2
  Silverman,     // K = 3/(πr²) · (1 − s)²:    ∫ (1 − s)² 2πd dd = πr²/3   (the 2D biweight)
};

inline float kernelWeight(Kernel k, float d2, float r2) {
  if (d2 > r2 || r2 <= 0) return 0.0f;
  float s = d2 / r2, norm = 1.0f / (kPi * r2);
  switch (k) {
    case Kernel::Uniform: return norm;
    case Kernel::Cone: return 3.0f * norm * (1.0f - std::sqrt(s));
    case Kernel::Epanechnikov: return 2.0f * norm * (1.0f - s);
    case Kernel::Silverman: return 3.0f * norm * (1.0f - s) * (1.0f - s);
  }
  return 0.0f;
}

// How a radiance estimate chooses its photons.
struct DensityEstimation {
  Kernel kernel = Kernel::Epanechnikov;
  int k = 50;             // k nearest photons, when radius == 0
  float radius = 0.0f;    // > 0: fixed-radius estimate
  float maxRadius = 0.0f; // > 0: cap on the k-NN radius
  // Photons farther than this from the query's tangent plane lie on another surface and are
  // skipped (Jensen's disc instead of a sphere). 0 = off. The photon integrator sets it to
  // a quarter of the (maximum) radius.
  float planeTolerance = 0.0f;
};

inline Kernel parseKernel(const std::string& name) {
  if (name == "uniform") return Kernel::Uniform;
  if (name == "cone") return Kernel::Cone;
  if (name == "epanechnikov") return Kernel::Epanechnikov;
  if (name == "silverman") return Kernel::Silverman;
  throw Error("--kernel: unknown kernel '" + name + "' (uniform, cone, epanechnikov, silverman)");
}

inline const char* kernelName(Kernel k) {
  switch (k) {
    case Kernel::Uniform: return "uniform";
    case Kernel::Cone: return "cone";
    case Kernel::Epanechnikov: return "epanechnikov";
    case Kernel::Silverman: return "silverman";
  }
  return "?";
}

}  // namespace pl
