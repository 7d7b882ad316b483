// Russian roulette (Arvo & Kirk 1990), its rules in one place. A path goes on with probability q
// and its weight is divided by q, which keeps an estimator unbiased for any q > 0; the rules
// differ only in how q is chosen, and each integrator names the one it uses. The arguments are
// the largest component of a throughput or weight (RGB or the path's wavelengths).
#pragma once
#include <algorithm>

namespace pl::roulette {

// The throughput rules play from the fourth bounce (depth 3, counted from 0): the first bounces
// of a path carry most of its contribution and cost little.
constexpr int kFirstDepth = 3;

// Throughput (pbrt-v4's PathIntegrator): q = min(1, max β · etaScale), etaScale = ∏ η² over the
// path's refractions. Radiance entering glass is compressed by 1/η² and expanded again on the
// way out; the path is no less important inside, so the rule divides the compression out
// (without it a path inside glass of η = 1.5 was cut with probability 56% at every bounce).
// Light paths carry no such compression (flux is not scaled at a refraction): etaScale = 1.
inline float throughput(float maxBeta, float etaScale = 1.0f) { return std::min(1.0f, maxBeta * etaScale); }

// Albedo (Jensen 2001, §5.2, photon tracing): q = min(1, max f·cos/pdf of this bounce), so that
// a surviving photon keeps the magnitude of its flux instead of shrinking bounce after bounce.
inline float albedo(float maxWeight) { return std::min(1.0f, maxWeight); }

// Expected contribution (Vorba & Křivánek 2016, adjoint-driven roulette without splitting): the
// rest of the path is expected to bring β·L̂, L̂ the incident radiance a guide predicts; against
// the pixel's value Ĩ it survives with q = clamp(W·β·L̂/Ĩ, floor, 1), W the weight window.
inline float expectedContribution(float beta, float incident, float pixel, float window, float floor) {
  return std::clamp(window * beta * incident / pixel, floor, 1.0f);
}

// Whether the path goes on: it draws u (only when q > 0, so that a certain end draws nothing)
// and survives when u < q. A q that is not above 0 (zero, or NaN from a broken weight) ends it.
template <typename Draw>
bool survives(float q, Draw&& draw) {
  return q > 0 && draw() < q;
}

}  // namespace pl::roulette
