// The progressive photon-mapping family: integrators that converge as passes of photons
// accumulate. An eye pass and a photon pass alternate; runPasses() is their shared loop.
#pragma once
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "core/budget.h"
#include "render/integrator.h"
#include "integrators/params.h"
#include "photon/photon_tracer.h"
#include "render/camera_path.h"
#include "render/checkpoints.h"
#include "render/renderer.h"
#include "render/session.h"

namespace pl {

struct ProgressiveOptions {
  int passes = 64;                   // INT32_MAX: until the time budget ends
  uint64_t photonsPerPass = 0;       // emitted photon paths per pass; 0 = the image's pixel count
  double alpha = 2.0 / 3.0;          // fraction of new photons kept; 2/3 minimises the MSE
  float radius = 0.0f;               // initial radius; 0 = defaultRadius()
  int maxDepth = 64;
  bool targetView = true;  // --photon-target view: photons from lights at infinity aimed at the view
  bool aimAreaLights = false;  // --aim-area-lights on: area lights' photons aimed at the view too
  bool adaptive = false;   // --photon-sampling adaptive: Hachisuka & Jensen 2011's chain (photon_tracer.h)
};
// What the three declare: passes, photons_per_pass, alpha, radius, max_depth, photon_target,
// aim_area_lights, photon_sampling.
// photonsPerPixel: photons_per_pass defaults to the pixel count (sppm and pppm, which re-trace
// their eye pass every pass), else to 100,000 (ppm, whose hit points are traced once).
std::vector<ParamSpec> progressiveParams(bool photonsPerPixel);
// From those parameters; passes unset (a time budget alone): unlimited.
ProgressiveOptions progressiveOptions(const ParamSet& p);

class PassIntegrator : public Integrator {
 public:
  explicit PassIntegrator(const ProgressiveOptions& options) : o_(options) {}
  const ProgressiveOptions& options() const { return o_; }

 protected:
  ProgressiveOptions o_;
};

// ---- shared pieces ----

// Per-pixel (or per-hit-point) statistics of PPM (Hachisuka, Ogaki, Jensen 2008), in double.
struct ProgressiveStats {
  double N = 0.0;    // accumulated photon count
  double R2 = 0.0;   // squared radius
  glm::dvec3 tau{0.0};  // accumulated (unnormalised) flux

  // M photons found inside the radius, carrying unnormalised flux Φ_M:
  //   N' = N + αM,  R'² = R² (N + αM)/(N + M),  τ' = (τ + Φ_M) R'²/R².
  // Photons from the back side are never counted in M, so they never shrink the radius.
  void update(double M, const glm::dvec3& phiM, double alpha) {
    if (M <= 0) return;
    double ratio = (N + alpha * M) / (N + M);
    N += alpha * M;
    R2 *= ratio;
    tau = (tau + phiM) * ratio;
  }
  // Radiance estimate after `emitted` photon paths in total: L = τ / (π R² N_emitted).
  glm::dvec3 radiance(double emitted) const { return R2 > 0 && emitted > 0 ? tau / (kPi * R2 * emitted) : glm::dvec3(0.0); }
};

// PPPM's global radius schedule (Knaus & Zwicker 2011): r²_{i+1} = r²_i (i + α)/(i + 1), i ≥ 1.
inline double pppmNextRadius2(double r2, int i, double alpha) { return r2 * (i + alpha) / (i + 1); }

// The first non-specular point along a camera ray, following mirrors and glass by sampling.
struct VisiblePoint {
  SurfaceHit hit;
  Vec3 wo;
  Spectrum beta{0.0f};  // throughput from the camera to the point
  bool valid = false;
};
// Returns the emission picked up on the way (light seen directly or through specular surfaces).
// PPM's hit points: all light there, direct included, comes from photons.
Spectrum traceVisiblePoint(const Scene& scene, Ray ray, SampledWavelengths& lambda, Rng& rng, int maxDepth, VisiblePoint* vp);

// The gather points of sppm and pppm, whose photons carry no direct light. At each non-specular
// vertex the direct light is a light and a BSDF sample under MIS (estimateDirectMIS). The path
// goes on through the first lobe too narrow for a photon gather (narrowLobe), as pbrt-v3's SPPM
// goes on through glossy surfaces; that vertex becomes `caustic`, which gathers only caustic
// photons (L S+ x: the light a continued path cannot find, a delta light through glass), and
// the next non-specular vertex becomes `vp`, which gathers caustic and indirect ones. Emission
// met through specular surfaces counts only before the first non-specular vertex: after it,
// it is that vertex's caustic photons. Every light path is counted once:
//   L x (direct, MIS) + L S+ x (caustic photons at x) + L … N S* x (N: the next point's gather).
// Returns the emission and direct light gathered on the way.
Spectrum traceGatherPoints(const Scene& scene, Ray ray, SampledWavelengths& lambda, Rng& rng, int maxDepth, VisiblePoint* vp,
                           VisiblePoint* caustic);

// A lobe narrower than a photon gather resolves: the BSDF's density towards the mirror
// direction of wo exceeds 1/Ω, Ω = kGatherLobe sr. A gather of tens of photons sees incident
// directions ~0.1–0.3 sr apart, so a narrower lobe weighs a few of them hugely and the rest not
// at all: the speckles of glossy metal under SPPM. For GGX (density ≈ G1/(4πα² cosθo) there)
// α below ~0.25 continues.
constexpr float kGatherLobe = 0.25f;
bool narrowLobe(const SurfaceHit& hit, const Vec3& woLocal, const SampledWavelengths& lambda);

// One photon pass's contribution at a visible point: the M photons of `accepted` path types
// inside the statistics' radius (same side, near the tangent plane) and their flux
// Φ_M = Σ β f(ωo, ωp) Φp (unnormalised by the pass's photon count), then the PPM update.
// With `marks`, the photons found are marked there.
void gatherPhotons(const VisiblePoint& vp, const PhotonMap& map, uint8_t accept, double photonsPerPass, double alpha,
                   ProgressiveStats* stats, PhotonMarks* marks = nullptr);
double meanRadius(const std::vector<ProgressiveStats>& stats);

// SPPM's and PPPM's photons per pass when unset: the image's pixel count, as pbrt-v4's SPPM, so
// that an eye pass costs about what a photon pass does: on a sky-lit model the eye pass's
// direct light is most of the error (docs: Progressive photon mapping).
inline uint64_t defaultPhotonsPerPass(int width, int height) { return uint64_t(width) * uint64_t(height); }

// The registry's resolve step for the progressive integrators: an unset radius becomes
// defaultRadius(), unset photons per pass defaultPhotonsPerPass(); returns the sentence the CLI
// prints about them.
std::string resolveProgressiveRadius(const Scene& scene, int width, int height, ParamSet& params);

// The render session of a progressive integrator (render/session.h; its budget is polled per
// pixel, per photon chunk, in the kd-tree build) and what it derives from its options before
// the first pass.
struct PassSetup : RenderSession {
  PassSetup(const Scene& scene, const RenderOptions& image, const ProgressiveOptions& options);
  const RenderOptions& image = options();  // resolution resolved
  float initialRadius;  // options.radius, or defaultRadius()
  uint64_t photonsPerPass;  // options.photonsPerPass, or the pixel count (defaultPhotonsPerPass)
  EmissionTarget target;    // with targetView: visibleEmissionTarget(), margin initialRadius
  // The visibility ratio (Hachisuka & Jensen 2011): of the photons the passes stored that a
  // gather could use (their path type accepted), the fraction some gather found.
  uint64_t photonsUsable = 0, photonsFound = 0;
  AdaptiveChainStats chain;  // the passes' adaptive chains, summed
  // The adaptive chain's mutation size d for the next pass: fixed within a pass, adapted
  // between passes towards the acceptance rate 0.234 with a diminishing step (Andrieu & Thoms
  // 2008), d ← d + (a_p − 0.234)/p.
  float mutationSize = 0.1f;
  int adaptedPasses = 0;
  void countVisibility(const PhotonMaps& maps, uint8_t accept, const PhotonMarks& marks) {
    photonsUsable += maps.global.count(accept);
    photonsFound += marks.count();
    chain.add(maps.chain);
    if (maps.chain.mutations) {
      const double rate = double(maps.chain.accepted) / double(maps.chain.mutations);
      mutationSize = std::clamp(float(mutationSize + (rate - 0.234) / ++adaptedPasses), 1e-4f, 1.0f);
    }
  }
  double visibleFraction() const { return photonsUsable ? double(photonsFound) / double(photonsUsable) : -1.0; }
  // Passes each pixel has completed: equal, except that a pass the budget cut short during its
  // gathers reached only some pixels, each pixel's estimate using its own count.
  std::vector<uint32_t> passes;
};

// The photons sppm and pppm gather and store: caustic and indirect ones (their direct light is
// estimateDirectMIS's).
constexpr uint8_t kGatheredPhotons = Photon::kAcceptIndirect | Photon::kAcceptCaustic;

// Photon maps for pass `pass`: independent per pass, deterministic for (seed, pass). When the
// budget expires on the way, the maps come back incomplete (and empty): the pass is dropped.
// With `adaptive`, the map comes from the adaptive chain towards it.
PhotonMaps tracePassPhotons(const Scene& scene, uint64_t seed, int pass, uint64_t photons, int threads, int maxDepth,
                            bool spectral, const Budget* budget, const EmissionTarget& target,
                            uint8_t store = Photon::kAcceptAll, const PhotonVisibility* adaptive = nullptr,
                            float mutationSize = 0.1f);

// A pass's visibility for adaptive photon sampling (null with uniform sampling): every pixel's
// gather points with their squared radii, which pointsOf(i, add) hands to add(point, r²).
template <class PointsOf>
std::unique_ptr<PhotonVisibility> passVisibility(const ProgressiveOptions& o, size_t pixels, PointsOf&& pointsOf) {
  if (!o.adaptive) return nullptr;
  std::vector<PhotonVisibility::Sphere> spheres;
  auto add = [&](const VisiblePoint& vp, double r2) {
    if (vp.valid) spheres.push_back({vp.hit.p, float(r2)});
  };
  for (size_t i = 0; i < pixels; ++i) pointsOf(i, add);
  return std::make_unique<PhotonVisibility>(spheres);
}

// The start of pixel (x, y)'s eye path in pass `pass` (PPM's single eye pass is pass 0).
inline CameraPath beginEyePath(const Scene& scene, const RenderOptions& image, int x, int y, uint64_t pass) {
  return beginCameraPath(scene, image, x, y, pass);
}

// In spectral mode the visible point's throughput β(λ) becomes the linear sRGB of white light
// through the specular chain, so that gathers (in RGB) can use it; then the path ends.
void finishSpectralVisiblePoint(const SampledWavelengths& lambda, VisiblePoint* vp, Spectrum* L);
void finishSpectralVisiblePoint(const SampledWavelengths& lambda, VisiblePoint* vp);  // β alone

// The loop all three share: runs pass(1), pass(2), ... until o.passes, the time limit or an
// interrupt. pass(p) returns whether its photons were traced (a pass the budget stops before
// that is dropped whole); within it, the integrator polls the budget per pixel and counts the
// pixels' completed passes in setup.passes. A slice (PPPM's --pass-range A:B:K) runs passes
// A + 1, A + 1 + K, ... up to B, and counts from its start.
template <typename PassFn, typename ImageFn, typename RadiusFn>
ImageRGB runPasses(PassSetup& setup, const ProgressiveOptions& o, RenderInfo* info, PassFn&& pass, ImageFn&& image,
                   RadiusFn&& meanRadius) {
  uint64_t tracedPasses = 0;
  auto infoAt = [&](bool last) {
    RenderInfo pi = setup.info(last);
    PixelCounts counts = summarizeCounts(setup.passes);
    pi.passes = counts.all;
    pi.meanWork = counts.mean;
    pi.photons = tracedPasses * setup.photonsPerPass;
    pi.meanRadius = meanRadius();
    pi.visibleFraction = setup.visibleFraction();
    if (setup.chain.uniform) pi.visiblePaths = setup.chain.visibleFraction();
    return pi;
  };
  auto runPass = [&](int p) {  // 0-based unit p is pass p + 1
    if (pass(p + 1)) ++tracedPasses;
    return true;
  };
  setup.run(setup.units(o.passes), runPass, infoAt, image);
  if (info) *info = infoAt(true);
  return image();
}
}  // namespace pl
