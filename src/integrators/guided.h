#pragma once
#include <memory>
#include <string>
#include <vector>

#include "guiding/guide.h"
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
// incident radiance (guiding/guide.h). It renders in iterations of 1, 2, 4, 8, ... samples per
// pixel; each samples with what the guide learned before it, so every iteration is an unbiased
// image on its own, and the image combines them.
class GuidedIntegrator final : public Integrator {
 public:
  explicit GuidedIntegrator(GuidedOptions options) : options_(std::move(options)) {}
  ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) override;
  const char* name() const override { return "guided"; }
  std::vector<std::string> notes() const override { return notes_; }

  // One camera path; with `record`, what it found is recorded into the guide (as `thread`).
  // `pixel`: the pixel's value as far as it is known (0: not yet), for Russian roulette.
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler, Guide& guide, bool record,
              int thread, float pixel) const;

  // The iteration schedule for `spp` samples per pixel: iteration k has 2^k samples, unless
  // fewer than twice that would be left after it; then it takes all that is left (2^k to
  // 3·2^k samples) and is the last, so that the best-trained distribution renders the most.
  static std::vector<int> schedule(int spp);

 private:
  GuidedOptions options_;
  std::vector<std::string> notes_;
};

}  // namespace pl
