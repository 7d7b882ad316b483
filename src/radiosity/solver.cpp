#include "radiosity/solver.h"

#include <cmath>

#include "core/parallel.h"
#include "radiosity/form_factor.h"

namespace pl {

// ---------------------------------------------------------------------------------------------
// Form factors: the upper triangle of pairs in 64×64 tiles. A tile (I, J) computes every pair
// (i in I, j in J, i < j) once and writes F_ij into tile (I, J) and F_ji into tile (J, I), both
// compact in memory; tiles are independent work items.

void computeFormFactors(const Scene& scene, const PatchMesh& mesh, int threads, const Budget& budget, FormFactorMatrix* F) {
  constexpr size_t kTile = 64;
  const size_t n = mesh.size();
  const auto& patches = mesh.patches();
  const size_t tiles = (n + kTile - 1) / kTile;
  std::vector<std::pair<uint32_t, uint32_t>> work;
  for (size_t I = 0; I < tiles; ++I)
    for (size_t J = I; J < tiles; ++J) work.emplace_back(uint32_t(I), uint32_t(J));
  std::vector<uint64_t> rays(resolveThreads(threads), 0);
  std::atomic<bool> stopped{false};
  parallelFor(work.size(), threads, [&](size_t w, int thread) {
    if (budget.expired()) {
      stopped = true;
      return;
    }
    const size_t i0 = work[w].first * kTile, j0 = work[w].second * kTile;
    for (size_t i = i0; i < std::min(n, i0 + kTile); ++i) {
      F->values[i * n + i] = 0.0f;  // a planar patch does not see itself
      for (size_t j = std::max(j0, i + 1); j < std::min(n, j0 + kTile); ++j) {
        FormFactorPair f = formFactors(scene, patches[i], patches[j]);
        F->values[i * n + j] = f.ij;
        F->values[j * n + i] = f.ji;
        rays[thread] += f.rays;
      }
    }
  });
  for (uint64_t r : rays) F->rays += r;
  F->complete = !stopped;
}

std::vector<Spectrum> deltaLightIrradiance(const Scene& scene, const PatchMesh& mesh, int threads) {
  std::vector<Spectrum> E(mesh.size(), Spectrum(0.0f));
  std::vector<const Light*> delta;
  for (const auto& light : scene.lights())
    if (light->isDelta()) delta.push_back(light.get());
  if (delta.empty()) return E;
  parallelFor(mesh.size(), threads, [&](size_t i, int) {
    for (const Light* light : delta) E[i] += directIrradiance(scene, *light, mesh.patches()[i]);
  });
  return E;
}

// ---------------------------------------------------------------------------------------------
// Gauss–Seidel: each sweep updates B_i in patch order from the newest B_j. Converges for ρ < 1
// (the matrix ρF has row sums ≤ max ρ < 1 in a closed scene, less in an open one).

RadiositySolution solveRadiosity(const PatchMesh& mesh, const FormFactorMatrix& F, std::vector<Spectrum> irradiance,
                                 double tolerance, int maxSweeps) {
  const size_t n = mesh.size();
  const auto& patches = mesh.patches();
  RadiositySolution s;
  s.irradiance = std::move(irradiance);
  // Channels apart, padded to a multiple of 8, so that the gathering loop vectorises.
  const size_t padded = (n + 7) / 8 * 8;
  std::vector<float> B[3];
  for (auto& b : B) b.assign(padded, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    Spectrum b = patches[i].exitance + patches[i].reflectance * s.irradiance[i];
    B[0][i] = b.r, B[1][i] = b.g, B[2][i] = b.b;
  }
  for (s.sweeps = 1; s.sweeps <= maxSweeps; ++s.sweeps) {
    double change = 0.0, total = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const float* row = F.row(i);
      float acc[3][8] = {};
      size_t j = 0;
      for (; j + 8 <= n; j += 8)
        for (int c = 0; c < 3; ++c)
          for (int k = 0; k < 8; ++k) acc[c][k] += row[j + k] * B[c][j + k];
      for (; j < n; ++j)
        for (int c = 0; c < 3; ++c) acc[c][0] += row[j] * B[c][j];
      const Patch& p = patches[i];
      double gathered[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 8; ++k) gathered[c] += acc[c][k];
      const float rho[3] = {p.reflectance.r, p.reflectance.g, p.reflectance.b};
      const float M[3] = {p.exitance.r, p.exitance.g, p.exitance.b};
      const float E[3] = {s.irradiance[i].r, s.irradiance[i].g, s.irradiance[i].b};
      for (int c = 0; c < 3; ++c) {
        float updated = M[c] + rho[c] * float(E[c] + gathered[c]);
        change += double(p.area) * std::abs(updated - B[c][i]);
        total += double(p.area) * updated;
        B[c][i] = updated;
      }
    }
    s.unshot = total > 0 ? change / total : 0.0;
    if (s.unshot <= tolerance) {
      s.converged = true;
      break;
    }
  }
  s.sweeps = std::min(s.sweeps, maxSweeps);
  s.radiosity.resize(n);
  for (size_t i = 0; i < n; ++i) s.radiosity[i] = Spectrum(B[0][i], B[1][i], B[2][i]);
  return s;
}

}  // namespace pl
