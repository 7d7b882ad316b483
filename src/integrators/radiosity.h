#pragma once
#include <memory>

#include "render/integrator.h"
#include "radiosity/patch_mesh.h"
#include "radiosity/solver.h"

namespace pl {

// The integrator around radiosity's solver (radiosity/solver.h): meshing, solving once, and
// showing the solution (flat, smooth or through a final gather).
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
