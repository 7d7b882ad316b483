// Classic radiosity's solver, independent of how the solution is shown.
#pragma once
#include <vector>

#include "core/budget.h"
#include "core/memory.h"
#include "radiosity/patch_mesh.h"
#include "scene/scene.h"

namespace pl {

// Classic radiosity (Goral et al. 1984; Cohen & Greenberg 1985; Cohen & Wallace 1993): the
// rendering equation restricted to diffuse surfaces and discretised into patches of constant
// radiosity B (W/m²),
//   B_i = M_i + ρ_i (E_i + Σ_j F_ij B_j),
// M_i = π·Le the patch's own exitance, E_i the irradiance the delta lights give it directly
// (they shoot first: a point light is not a patch), F_ij the form factors (radiosity/
// form_factor.h). The linear system is solved by Gauss–Seidel until the power a sweep still
// changes, Σ A_i |ΔB_i|, is below `tolerance` times the power leaving all patches. A diffuse
// surface's radiance is L = B/π in every direction, which is what the camera sees.
//
// Form factors are computed once, all n² of them (with reciprocity's pair shared: one set of
// visibility rays gives F_ij and F_ji), and stored as floats: 4n² bytes, 400 MB at 10 k
// patches, 1.6 GB at 20 k. Progressive refinement (Cohen et al. 1988) would need one row at a
// time but recomputes a patch's row, with rays, each time the patch shoots again (Gauss–Seidel
// needs 9 sweeps in the Cornell box, shooting a comparable number of shots per patch); with
// the matrix in memory a sweep costs n² multiply-adds instead of n² rays.
// n×n form factors, row i holding F_ij for every j.
struct FormFactorMatrix {
  explicit FormFactorMatrix(size_t n) : n(n), values(n * n) {}
  const float* row(size_t i) const { return &values[i * n]; }
  size_t n;
  LargeArray<float> values;
  uint64_t rays = 0;
  bool complete = false;  // false when the budget stopped the computation
};

// Every pair's form factors, in parallel tiles; deterministic (each entry depends only on its
// pair). Polls the budget per tile.
void computeFormFactors(const Scene& scene, const PatchMesh& mesh, int threads, const Budget& budget, FormFactorMatrix* F);

struct RadiositySolution {
  std::vector<Spectrum> radiosity;  // B per patch, W/m²
  std::vector<Spectrum> irradiance; // E from the delta lights, W/m²
  int sweeps = 0;
  double unshot = 0.0;              // Σ A|ΔB| of the last sweep / Σ A·B
  bool converged = false;
};

// The delta lights' direct irradiance on every patch (parallel, deterministic).
std::vector<Spectrum> deltaLightIrradiance(const Scene& scene, const PatchMesh& mesh, int threads);

// Gauss–Seidel on B = M + ρ(E + F·B).
RadiositySolution solveRadiosity(const PatchMesh& mesh, const FormFactorMatrix& F, std::vector<Spectrum> irradiance,
                                 double tolerance, int maxSweeps);

}  // namespace pl
