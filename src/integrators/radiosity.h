#pragma once
#include <memory>

#include "core/memory.h"
#include "integrators/integrator.h"
#include "radiosity/patch_mesh.h"

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
struct RadiosityOptions {
  float patchSize = 0.0f;   // metres; 0: the size that fits patchBudget
  size_t patchBudget = 4096;
  double tolerance = 1e-4;  // unshot power / emitted power at which the solve stops
  int maxSweeps = 1000;
  // How the solution is shown: flat (B/π per patch), smooth (B interpolated from vertex
  // radiosities, the classic look) or gather (one final-gather bounce from the eye: direct
  // light by shadow rays, exactly, and the solution's reflected radiosity one bounce away).
  enum class Display { Flat, Smooth, Gather } display = Display::Smooth;
  bool patchesAov = false;  // also write OUT.patches.ext: flat patches with their edges drawn
};

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

class RadiosityIntegrator final : public PixelIntegrator {
 public:
  explicit RadiosityIntegrator(RadiosityOptions o) : o_(o) {}
  void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) override;
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) override;
  const char* name() const override { return "radiosity"; }
  std::vector<std::string> warnings() const override { return warnings_; }
  std::vector<std::string> notes() const override { return notes_; }
  std::vector<NamedImage> extraImages() const override { return extra_; }

  // What the solve cost (after render()).
  struct Stats {
    double meshSeconds = 0, formFactorSeconds = 0, solveSeconds = 0;
    uint64_t rays = 0;        // visibility rays of the form factors
    uint64_t matrixBytes = 0;
  };
  const Stats& stats() const { return stats_; }
  const PatchMesh& mesh() const { return *mesh_; }
  const RadiositySolution& solution() const { return solution_; }

 private:
  // Radiance leaving the hit's front towards w: B/π, flat or interpolated; −1 patch: black.
  Spectrum shade(const SurfaceHit& hit, const Vec3& w, const std::vector<Spectrum>& vertexValues,
                 const std::vector<Spectrum>& patchValues, bool smooth) const;

  RadiosityOptions o_;
  std::unique_ptr<PatchMesh> mesh_;
  RadiositySolution solution_;
  std::vector<Spectrum> vertexRadiosity_, reflected_, vertexReflected_;
  std::vector<std::string> warnings_, notes_;
  std::vector<NamedImage> extra_;
  Stats stats_;
  bool solved_ = false;
};

}  // namespace pl
