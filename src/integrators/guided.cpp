// Path guiding (`--integrator guided`), readable top to bottom: the camera path with its mixture
// of BSDF and guide sampling and the records it leaves, the training hook that schedules the
// iterations and trains the guide between them (the pixel loop, render/renderer.cpp, runs their
// passes and combines their images), the registration.
#include "integrators/guided.h"

#include <cmath>
#include <limits>

#include "integrators/builtins.h"
#include "integrators/path.h"
#include "integrators/path_step.h"
#include "render/checkpoints.h"

namespace pl {

// --- one camera path ---------------------------------------------------------------------------

namespace {

// A vertex whose direction was sampled from the mixture: where the path was, which way it went
// and with what density, its throughput after the scattering weight (before Russian roulette,
// so that paths roulette ended count as the zero estimates they are), and the radiance gathered
// before it left. What arrives later, divided by that throughput, is one estimate of the light
// incident at the vertex from that direction (Müller et al. 2017, §4).
// Plain floats: an array of 64 GLM vectors would be zeroed on every path (GLM_FORCE_CTOR_INIT).
struct PathVertex {
  uint32_t leaf;
  float wi[3], pdf, beta[3], before[3];
};
constexpr int kRecordedVertices = 64;  // deeper vertices are not recorded (they carry ~nothing)
// Russian roulette (GuidedSampling::survives): the weight window's factor, the least survival
// probability, and the bounce from which a path without the guide's estimate faces the path
// tracer's roulette (how they were chosen: docs explanation/guiding.md).
constexpr float kWindow = 5.0f, kFloor = 0.1f;
constexpr int kFallbackDepth = 8;

// The guided path's strategy for the shared vertex step (path_step.h): directions from a
// mixture of the BSDF and the guide, roulette by expected contribution, and the records the
// guide trains on.
class GuidedSampling {
 public:
  GuidedSampling(const Guide& guide, float bsdfFraction, bool record, float pixel)
      : guide_(guide), bsdfFraction_(bsdfFraction), record_(record), pixel_(pixel) {}

  void attenuate(const Spectrum& transmittance) { rouletteBeta_ *= transmittance; }

  // The guide at this point, on the side of the surface the path is on (the geometric normal
  // turned towards it); where it knows nothing the BSDF samples alone (α = 1). Looked up before
  // next-event estimation so that its top levels load while the shadow ray is traced.
  void arrive(const SurfaceHit& hit, const Ray& ray) {
    delta_ = hit.bsdf->isSpecular();
    here_ = delta_ ? GuideLookup{nullptr, 0} : guide_.at(hit.p, glm::dot(hit.ng, ray.d) < 0 ? hit.ng : -hit.ng);
    if (here_.distribution) here_.distribution->prefetch();
    alpha_ = here_.distribution && !here_.distribution->empty() ? bsdfFraction_ : 1.0f;
  }

  // One-sample MIS: the BSDF with probability α, the guide otherwise; the weight is
  // f·|cosθ|/(α p_bsdf + (1 − α) p_guide) whichever drew the direction (Veach's balance
  // heuristic for one sample), so the estimate is unbiased for any guide, and bounded by 1/α
  // times BSDF sampling's where the guide is poor. MIS against next-event estimation uses BSDF
  // sampling's density alone (misPdf): the weights of a path over the techniques that can make
  // it need only sum to one, h(p_light, p_bsdf) + h(p_bsdf, p_light) = 1, and the guide's density
  // for the light's direction would cost a quadtree descent at every vertex (docs
  // explanation/guiding.md).
  bool scatter(const SurfaceHit& hit, const Vec3& wo, SampledWavelengths& lambda, Sampler& sampler, ScatterSample* s) {
    const BSDFContext bc = bsdfContext(hit, lambda);
    const DirectionalQuadtree* guide = here_.distribution;
    guidePdf_ = 0.0f;
    const float uSelect = alpha_ < 1.0f ? sampler.get1D() : 0.0f;
    Vec2 u = sampler.get2D();
    if (uSelect < alpha_) {
      BSDFSample bs;
      if (!hit.bsdf->sample(wo, bc, u, sampler.get1D(), &bs)) return false;
      if (bs.terminatesSecondary) lambda.terminateSecondary();
      s->wiLocal = bs.wi;
      s->wiWorld = hit.shading.toWorld(bs.wi);
      s->eta = bs.eta;
      s->delta = bs.delta;
      s->misPdf = bs.pdf;
      unguided_ = bs.weight;
      if (bs.delta || alpha_ == 1.0f) {
        // Only the BSDF can draw a delta lobe, and where α = 1 it is the only technique.
        s->weight = bs.weight / alpha_;
        s->pdf = bs.pdf * alpha_;
      } else {
        guidePdf_ = guide->pdf(s->wiWorld);
        s->pdf = alpha_ * bs.pdf + (1 - alpha_) * guidePdf_;
        s->weight = s->pdf > 0 ? hit.bsdf->eval(wo, s->wiLocal, bc) * (std::abs(s->wiLocal.z) / s->pdf) : Spectrum(0.0f);
      }
    } else {
      s->wiWorld = guide->sample(u, &guidePdf_);
      s->wiLocal = hit.shading.toLocal(s->wiWorld);
      const float bsdfPdf = hit.bsdf->pdf(wo, s->wiLocal, bc);
      s->misPdf = bsdfPdf;
      s->pdf = alpha_ * bsdfPdf + (1 - alpha_) * guidePdf_;
      const Spectrum fCos = hit.bsdf->eval(wo, s->wiLocal, bc) * std::abs(s->wiLocal.z);
      s->weight = s->pdf > 0 ? fCos / s->pdf : Spectrum(0.0f);
      unguided_ = bsdfPdf > 0 ? fCos / bsdfPdf : s->weight;
      s->eta = 1.0f;
      s->delta = false;
    }
    sampledDelta_ = s->delta;
    cosine_ = std::abs(s->wiLocal.z);
    return !isBlack(s->weight);  // a zero weight ends the path: nothing it finds could count
  }

  void scattered(const PathState& p, const SurfaceHit&, const ScatterSample& s) {
    rouletteBeta_ *= unguided_;
    if (record_ && !delta_ && recorded_ < kRecordedVertices)
      vertices_[recorded_++] = {here_.leaf, {s.wiWorld.x, s.wiWorld.y, s.wiWorld.z}, s.pdf,
                                {p.beta.r, p.beta.g, p.beta.b}, {p.L.r, p.L.g, p.L.b}};
  }

  // Russian roulette by expected contribution where the guide knows it (adjoint-driven roulette,
  // Vorba and Křivánek 2016, without splitting): the rest of the path is expected to bring
  // β·L̂_i(x, ω), L̂_i from the guide (DirectionalQuadtree::radianceScale), against the pixel's
  // value Ĩ from the iterations before. The path tracer's rule on β would end exactly the paths
  // the guide sends where light comes from (their weight f·cos/p is small because p is high).
  // Elsewhere (no pixel value yet, no learned guide here, a specular bounce): the throughput
  // rule from kFallbackDepth on β′, the product of BSDF sampling's weights f·cos/p_bsdf, which
  // the guide does not shrink (with no guide β′ = β). Any q > 0 keeps the estimate unbiased.
  bool survives(PathState& p, Sampler& sampler) {
    float incident = guidePdf_ > 0 ? here_.distribution->radianceScale() * guidePdf_ : 0.0f;
    if (guidePdf_ > 0 && here_.distribution->cosineWeighted()) incident /= std::max(cosine_, 0.1f);
    if (pixel_ > 0 && incident > 0 && !sampledDelta_) {
      const float q = roulette::expectedContribution(average(p.beta), incident, pixel_, kWindow, kFloor);
      if (q < 1) {
        if (!roulette::survives(q, [&] { return sampler.get1D(); })) return false;
        p.beta /= q;
        rouletteBeta_ /= q;
      }
    } else if (p.depth >= kFallbackDepth) {
      const float q = roulette::throughput(maxComponent(rouletteBeta_), p.etaScale);
      if (!roulette::survives(q, [&] { return sampler.get1D(); })) return false;
      p.beta /= q;
      rouletteBeta_ /= q;
    }
    return true;
  }

  // What each recorded vertex received through its direction: the radiance gathered after it,
  // over its throughput, recorded divided by the density it was sampled with.
  void train(Guide& guide, const Spectrum& L, int thread) const {
    for (int i = 0; i < recorded_; ++i) {
      const PathVertex& v = vertices_[i];
      float incident = 0;
      for (int c = 0; c < 3; ++c) incident += v.beta[c] > 0 ? std::max(0.0f, L[c] - v.before[c]) / v.beta[c] : 0.0f;
      guide.record(v.leaf, Vec3(v.wi[0], v.wi[1], v.wi[2]), incident / 3 / v.pdf, thread);
    }
  }

 private:
  const Guide& guide_;
  const float bsdfFraction_;
  const bool record_;
  const float pixel_;
  Spectrum rouletteBeta_{1.0f};  // β′: the throughput with BSDF sampling's weights (the fallback rule's)
  // The vertex at hand: whether its BSDF is specular, the guide there, α, and what scatter drew.
  bool delta_ = false, sampledDelta_ = false;
  GuideLookup here_{nullptr, 0};
  float alpha_ = 1.0f, guidePdf_ = 0.0f, cosine_ = 0.0f;
  Spectrum unguided_{0.0f};  // f·|cosθ|/p_bsdf: the weight BSDF sampling alone gives the direction
  PathVertex vertices_[kRecordedVertices];
  int recorded_ = 0;
};

}  // namespace

Spectrum GuidedIntegrator::Li(const Ray& cameraRay, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler,
                              Guide& guide, bool record, int thread, float pixel) const {
  SurfaceHit first;
  const bool found = scene.intersect(cameraRay, &first);
  GuidedSampling strategy(guide, options_.bsdfFraction, record, pixel);
  const Spectrum L = tracePath(scene, cameraRay, found ? &first : nullptr, lambda, sampler, options_.maxDepth, strategy);
  strategy.train(guide, L, thread);
  return L;
}

// --- the training hook: the iterations' schedule --------------------------------------------

std::vector<int> GuidedIntegrator::schedule(int spp) {
  std::vector<int> n;
  int64_t used = 0;
  for (int k = 0; used < spp; ++k) {
    int64_t samples = int64_t(1) << std::min(k, 30);
    if (spp - used - samples < 2 * samples) samples = spp - used;
    n.push_back(int(samples));
    used += samples;
  }
  return n;
}

void GuidedIntegrator::LiPacket(CameraSample* samples, int n, const Scene& scene) const {
  for (int k = 0; k < n; ++k) {
    CameraSample& c = samples[k];
    c.L = unguided_ ? pathTracer_.Li(c.ray, scene, *c.lambda, *c.sampler)
                    : Li(c.ray, scene, *c.lambda, *c.sampler, *guide_, record_, c.thread, c.pixelEstimate);
  }
}

Spectrum GuidedIntegrator::Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const {
  return guide_ ? Li(ray, scene, lambda, sampler, *guide_, false, 0, 0.0f) : pathTracer_.Li(ray, scene, lambda, sampler);
}

// With a sample count: the fixed schedule. With a time budget alone: iterations double while the
// time left after the next would still pay for one twice as long (measured seconds per sample of
// the iteration before), and the last runs until the budget is spent.
//
// The unguided fallback. Guiding pays only where its lower variance per sample outweighs its
// higher cost per sample: the efficiency of an estimator is 1/(σ²·t), σ² the variance of one
// sample and t its time. Where a guided sample's lower variance does not pay for its higher cost
// (the plain Cornell box: docs explanation/guiding.md), the guide loses time it cannot win back.
// With a time budget alone and fallback = auto, when the schedule reaches its last iteration a
// short unguided iteration (a sixteenth of the last guided one's samples, at least 4 spp)
// measures the path tracer's σ²·t beside the last guided iteration's, and the last iteration
// renders with whichever is lower. σ² is relative, as relMSE weighs errors (IterationReport): the
// absolute variance is the bright pixels', and on Veach's door, where the guide's gain is in the
// dim room, it chose path tracing. Every iteration, guided or not, is an unbiased image of the
// same pixels, so the inverse-variance combination stays unbiased; the probe's samples count in
// the image like any iteration's. The guided iteration's t includes its recording, which the last
// iteration would not do, so close calls go to path tracing. Preparing the guide (a fresh photon
// map for the photon guide, a tree refit for the SD-tree) is not a cost per sample: the last
// iteration pays it once, out of the time left T, and samples in T − P. For equal variance of the
// remaining image, guided wins when σ_g²·t_g·T/(T − P) < σ_p²·t_p, t_g its seconds per sample
// without P, P the last guided iteration's preparation (at the small budgets where the schedule
// reaches its last iteration after a few samples, P dominated t_g and sent every photon-guided
// render to path tracing). With a sample count (no time budget) the schedule is kept: samples,
// not time, are the budget.
Iteration GuidedIntegrator::beforeIteration(const Scene& scene, int k, const RenderOptions& o, int threads,
                                            const Budget& budget) {
  if (k == 0) {
    GuideOptions go = options_.guideOptions;
    go.maxDepth = options_.maxDepth;
    go.spectral = o.spectral;
    guide_ = options_.guide == "photons" ? makePhotonGuide(scene, go) : makeSDTreeGuide(scene, go);
    const int target = unitTarget(o.spp, o.timeLimit);
    run_ = Schedule{};
    run_.fixed = target < INT_MAX ? schedule(target) : std::vector<int>();
    run_.timeLimit = o.timeLimit;
  }
  Schedule& r = run_;
  const bool autoFallback = options_.fallback == "auto" && r.fixed.empty();
  const bool alwaysFallback = options_.fallback == "always";
  int samples;
  bool last, unguided = false, probe = false;
  if (!r.fixed.empty()) {
    if (size_t(k) >= r.fixed.size()) return {};
    samples = r.fixed[size_t(k)];
    last = size_t(k) + 1 == r.fixed.size();
    unguided = last && alwaysFallback;
  } else if (r.probed) {
    last = true, unguided = r.unguidedWins;
    samples = INT_MAX - r.done;
  } else {
    samples = 1 << std::min(k, 24);
    const double left = o.timeLimit - budget.elapsed();
    last = k > 0 && left < 3 * r.secondsPerSample * samples;
    // Any guided iteration before the last gives σ²·t to compare with. (This asked for three
    // once; where photon tracing is slow, under the sanitizers, the schedule reached its last
    // iteration after two and skipped the probe.)
    if (last && autoFallback && r.guidedIterations > 0) {
      last = false, unguided = probe = true;
      samples = std::max(4, r.guidedSamples / 16);
    } else if (last) {
      unguided = alwaysFallback;
      samples = INT_MAX - r.done;
    }
  }
  if (!unguided) {
    guide_->prepare(scene, r.guidedIterations++, samples, last, o.seed, threads, budget);
    if (budget.expired()) return {};
    r.guideSize = guide_->describe();
  }
  unguided_ = unguided, probe_ = probe, last_ = last;
  record_ = !unguided && guide_->learns() && !last;
  return {samples, last, options_.combine == "last"};
}

void GuidedIntegrator::afterIteration(const IterationReport& report) {
  Schedule& r = run_;
  r.done += report.least;
  ++r.iterations;
  r.lastSamples = report.least;
  r.variances.push_back(report.variance);
  r.secondsPerSample = report.seconds / std::max(1, report.samples);
  if (probe_) {
    r.unguidedCost = report.relativeVariance * r.secondsPerSample;
    const double left = r.timeLimit - report.elapsed;
    r.guidedCost = left > r.prepareSeconds ? r.guidedRelative * r.guidedSeconds * left / (left - r.prepareSeconds)
                                           : std::numeric_limits<double>::infinity();
    r.unguidedWins = r.unguidedCost < r.guidedCost;
    r.probed = true;
  } else if (!unguided_ && !last_) {
    r.guidedRelative = report.relativeVariance;
    r.guidedSeconds = (report.seconds - report.trainingSeconds) / std::max(1, report.samples);
    r.prepareSeconds = report.trainingSeconds;
    r.guidedCost = r.guidedRelative * r.guidedSeconds;  // reported as measured, without P, if no probe follows
    r.guidedSamples = report.samples;
  }
  if (last_ && unguided_) r.guideSize += "; the last iteration path-traced";
}

std::vector<std::string> GuidedIntegrator::notes() const {
  const Schedule& r = run_;
  if (!guide_) return {};
  std::string sigma;
  for (double v : r.variances) sigma += (sigma.empty() ? "" : ", ") + formatNumber(float(v));
  std::vector<std::string> notes = {
      std::to_string(r.iterations) + " iterations (the last " + std::to_string(r.lastSamples) + " spp), " +
          (options_.combine == "last" ? "the last alone" : "combined by inverse variance") + "; guide: " + r.guideSize,
      "variance of one sample, iteration by iteration: " + sigma};
  if (r.probed)
    notes.push_back("unguided fallback: variance x seconds per sample " + formatNumber(float(r.unguidedCost)) +
                    " path-traced against " + formatNumber(float(r.guidedCost)) + " guided (its preparation, " +
                    formatNumber(float(r.prepareSeconds)) + " s, paid once from the time left): the last iteration " +
                    (r.unguidedWins ? "path-traced" : "guided"));
  return notes;
}

// --- registration ------------------------------------------------------------------------------

namespace {

std::vector<ParamSpec> guidedParams() {
  ParamSpec guide = params::choice(
      "guide", "what the guide learns from: the render's own paths (SD-tree) or photons' incident directions", "sdtree",
      {"sdtree", "photons"});
  ParamSpec fraction{"bsdf_fraction", ParamType::Real, "probability of sampling the BSDF instead of the guide", "0.5"};
  fraction.lo = 0, fraction.hi = 1, fraction.openLow = true;
  ParamSpec combine = params::choice("combine", "how iterations make the image: weighted by inverse variance, or the last alone",
                                     "inverse-variance", {"inverse-variance", "last"});
  ParamSpec spatial{"spatial_threshold", ParamType::Real,
                    "sdtree: c, a spatial leaf splits past c·√spp records in one iteration (Müller et al.: 12000)", "12000"};
  spatial.lo = 1, spatial.hi = 1e12;
  ParamSpec photons{"photons", ParamType::Integer, "photons: emitted photon paths for the first iteration's map (doubling for five iterations)",
                    "100000"};
  photons.lo = 1, photons.hi = 4294967295.0;
  ParamSpec k{"k", ParamType::Integer, "photons: the nearest photons each cached distribution is built from", "256"};
  k.lo = 8, k.hi = 100000;
  ParamSpec fallback = params::choice(
      "fallback",
      "the last iteration path-traces: auto (with a time budget alone) when a short unguided iteration shows path tracing "
      "more efficient, variance x time per sample, than the guide; off: never; always",
      "auto", {"auto", "off", "always"});
  return {params::spp(), params::maxDepth(), guide, fraction, combine, fallback, spatial, photons, k};
}

}  // namespace

IntegratorEntry guidedEntry() {
  return IntegratorEntry(
      "guided", "path guiding: path tracing with directions from a learned incident-light distribution (SD-tree or photons)",
      IntegratorFamily::Pixel, nullptr,
      guidedParams(),
      [](const ParamSet& p, const RenderOptions&) {
        GuidedOptions o;
        o.maxDepth = int(p.integer("max_depth"));
        o.guide = p.choice("guide");
        o.bsdfFraction = float(p.real("bsdf_fraction"));
        o.combine = p.choice("combine");
        o.fallback = p.choice("fallback");
        o.guideOptions.spatialThreshold = p.real("spatial_threshold");
        o.guideOptions.photons = uint64_t(p.integer("photons"));
        o.guideOptions.photonsPerDistribution = int(p.integer("k"));
        return std::make_unique<GuidedIntegrator>(o);
      });
}


}  // namespace pl
