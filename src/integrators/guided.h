#pragma once
#include <memory>
#include <string>
#include <vector>

#include "guiding/guide.h"
#include "integrators/path.h"
#include "render/integrator.h"

namespace pl {

struct GuidedOptions {
  int maxDepth = 64;
  std::string guide = "sdtree";  // sdtree | photons
  // One-sample MIS between the BSDF and the guide (Müller et al. 2017, §4): the BSDF is chosen
  // with this probability, the guide otherwise, and every direction is weighted by the mixture
  // density α p_bsdf + (1 − α) p_guide, so that neither technique's weak spots dominate. (MIS
  // against next-event estimation uses p_bsdf alone: guided.cpp.)
  float bsdfFraction = 0.5f;
  // How iterations are combined into the image: weighted by inverse variance, or the last alone.
  std::string combine = "inverse-variance";
  // Whether the last iteration may path-trace instead (guided.cpp, "the unguided fallback"):
  // "auto" with a time budget alone, when a short unguided iteration shows path tracing the more
  // efficient (variance × time per sample); "off" never; "always" every time (for comparisons).
  std::string fallback = "auto";
  GuideOptions guideOptions;
};

// Path guiding: a path tracer (next-event estimation and MIS, as integrators/path.cpp) whose
// direction at each non-specular vertex comes from the BSDF or from a learned distribution of
// incident radiance (guiding/guide.h). A pixel integrator with a training hook: it renders in
// iterations of 1, 2, 4, 8, ... samples per pixel, each sampling with what the guide learned
// before it, so every iteration is an unbiased image on its own, and the pixel loop combines them.
class GuidedIntegrator final : public PixelIntegrator, private TrainingHook {
 public:
  explicit GuidedIntegrator(GuidedOptions options)
      : options_(std::move(options)), pathTracer_(options_.maxDepth, /*sobol=*/false, /*lanes=*/false, /*spectral=*/false) {}
  const char* name() const override { return "guided"; }
  std::vector<std::string> notes() const override;
  TrainingHook* training() override { return this; }

  // A guided path with the guide as trained so far, recording nothing (before a render has
  // trained one: the path tracer's).
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  // This iteration's paths: guided (recording where the guide learns), or path-traced where the
  // schedule chose the unguided fallback.
  void LiPacket(CameraSample* samples, int n, const Scene& scene) const override;

  // One camera path; with `record`, what it found is recorded into the guide (as `thread`).
  // `pixel`: the pixel's value as far as it is known (0: not yet), for Russian roulette.
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler, Guide& guide, bool record,
              int thread, float pixel) const;

  // The iteration schedule for `spp` samples per pixel: iteration k has 2^k samples, unless
  // fewer than twice that would be left after it; then it takes all that is left (2^k to
  // 3·2^k samples) and is the last, so that the best-trained distribution renders the most.
  static std::vector<int> schedule(int spp);

 private:
  Iteration beforeIteration(const Scene& scene, int index, const RenderOptions& options, int threads,
                            const Budget& budget) override;
  void afterIteration(const IterationReport& report) override;

  GuidedOptions options_;
  // Its Li is called one sample at a time, so the lanes (a batch of rows) do not apply.
  const PathIntegrator pathTracer_;
  std::unique_ptr<Guide> guide_;
  // What one render's schedule has measured and decided (guided.cpp, beforeIteration).
  struct Schedule {
    std::vector<int> fixed;  // with a sample count: the iterations' samples
    double timeLimit = 0;
    int done = 0;            // samples per pixel every pixel has
    int iterations = 0, lastSamples = 0, guidedIterations = 0, guidedSamples = 0;
    double secondsPerSample = 0;
    bool probed = false, unguidedWins = false;
    double guidedCost = 0, unguidedCost = 0;  // σ²·t of the last guided iteration and of the probe
    double guidedRelative = 0, guidedSeconds = 0, prepareSeconds = 0;  // its σ², t_g and P
    std::string guideSize;
    std::vector<double> variances;  // each iteration's σ² of one sample, for the notes
  } run_;
  // The iteration under way: path-traced (the fallback), the fallback's probe, the last, recording.
  bool unguided_ = false, probe_ = false, last_ = false, record_ = false;
};

}  // namespace pl
