// A directional albedo E(μ, roughness), μ and roughness in [0, 1], tabulated on a regular grid
// of nodes and read bilinearly: what energy-conserving layers and lobes look up per evaluation
// (bsdfs/metallic_roughness.cpp, bsdfs/sheen.cpp).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

namespace pl {

// The node below x ∈ [0, 1] of n regular nodes, and x's fraction of the way to the next.
inline void lerpNodes(float x, int n, int* i0, float* t) {
  float f = std::clamp(x, 0.0f, 1.0f) * (n - 1);
  *i0 = std::min(int(f), n - 2);
  *t = f - *i0;
}

template <int NMu, int NRough>
struct AlbedoGrid {
  static constexpr int nMu = NMu, nRough = NRough;
  std::array<std::array<float, NMu>, NRough> E{};  // E[roughness node][μ node]

  static float mu(int j) { return float(j) / (nMu - 1); }
  static float roughness(int k) { return float(k) / (nRough - 1); }
  float operator()(float cosTheta, float roughness) const {
    int j, k;
    float tj, tk;
    lerpNodes(std::abs(cosTheta), nMu, &j, &tj);
    lerpNodes(roughness, nRough, &k, &tk);
    auto row = [&](int r) { return (1 - tj) * E[r][j] + tj * E[r][j + 1]; };
    return (1 - tk) * row(k) + tk * row(k + 1);
  }
};

}  // namespace pl
