// Vertex connection and merging, with bidirectional path tracing and bidirectional photon
// mapping as its two halves. Read top to bottom: the iteration's constants, the light subpaths
// (stored, and connected to the camera), the camera subpaths (emission found, next-event
// estimation, connections to the light subpath of the same index, merges with every light
// vertex nearby), the render loop, the registration.
//
// Notation. A light subpath y₀ y₁ … has s vertices, a camera subpath z₀ z₁ … t vertices (z₀ the
// pinhole); technique (s, t) joins them with one edge, so a path of k bounces (s + t − 2 = k)
// has k + 3 techniques: s = 0 (the camera path hits an emitter), s = 1 (next-event estimation),
// s ≥ 2 with t ≥ 2 (connect y_{s−1} to z_{t−1}), t = 1 (connect y_{s−1} to the camera: light
// tracing, splatted). Merging joins y_{s−1} and z_{t−1} where they lie within r of each other: a
// photon-map density estimate, unbiased only as r → 0.
//
// MIS. Each technique's weight is the power heuristic w_i = p_i² / Σ_j p_j² over all techniques
// that could make the same path (--heuristic balance: w_i = p_i / Σ_j p_j). Instead of
// re-walking the path for every p_j (O(n²)), each subpath carries three running sums of pdf
// ratios (Georgiev 2012, "Implementing VCM", eqs. 31–36), updated once per vertex:
//   dVCM  the ratio for the technique that ends the subpath here (connect or merge at it),
//   dVC   the sum for every connection further back along the subpath,
//   dVM   the sum for every merge further back,
// and a connection or merge weighs itself against both sides in O(1) (eqs. 37–45). With N
// light paths an iteration, merging at a vertex is η = N·πr² times likelier than connecting
// there (eq. 20); bdpt sets the merge terms to 0, bpm the connection terms.
//
// Densities are converted between solid angle and area with the geometric normal (the measure
// the path lives in); the BSDF's cosines in the contributions are the shading normal's, and the
// light side evaluates its BSDFs for importance, with Veach's shading-normal correction, as the
// light tracer does. Russian roulette (on the throughput, as the path tracer and light tracer)
// is left out of the weights: they are still a partition of unity for every path, which is all
// unbiasedness needs.
#include "integrators/bidirectional.h"

#include <atomic>
#include <cmath>

#include "core/roulette.h"
#include "core/sampler.h"
#include "core/parallel.h"
#include "integrators/builtins.h"
#include "photon/hash_grid.h"
#include "render/visible_probe.h"
#include "render/camera_path.h"
#include "render/session.h"
#include "transport/light_walk.h"

namespace pl {

namespace {
// The heuristic's ratio term, ratio^β: β = 2 the power heuristic (Veach 1997 §9.2.4, the
// default), β = 1 the balance heuristic. Every weight is 1/(Σ ratio^β) over the techniques.
inline float misTerm(float ratio, bool balance) { return balance ? ratio : ratio * ratio; }
// A dispersive refraction scales the hero wavelength by the number of wavelengths (3) and zeroes
// the others; a path whose two halves both did so must count that scale once.
constexpr float kWavelengths = 3.0f;
}  // namespace

// --sampler sobol (core/sampler.h) covers each subpath's first kSamplerSlots draws. Eight
// slots reach the second vertex of either subpath, where the stratification pays; 32 gave the
// same error on SmallVCM's box at equal iterations, and each point costs ~150 instructions.
constexpr int kSamplerSlots = 8;

// ---------------------------------------------------------------------------------------------
// One iteration's constants (tech. rep. §4.3). N light paths, one camera path per pixel.
struct VertexConnectionMerging::Iteration {
  int width = 0, height = 0;
  float pixels = 0;      // W·H
  float lightPaths = 0;  // N (= W·H)
  float radius = 0;
  float misVm = 0;           // Mis(η), η = N·πr²: merging over connecting at one vertex
  float misVc = 0;           // Mis(1/η)
  float vmNormalization = 0; // 1/(N·πr²): the uniform kernel, over N paths
};

// A subpath being traced. dVCM, dVC, dVM as above; `specular`: every scattering so far was a
// delta lobe (then only emission can find the path under bpm).
struct VertexConnectionMerging::SubPath {
  Ray ray;
  Spectrum beta{1.0f};  // camera: ∏ f cos / pdf; light: flux carried (W)
  Spectrum throughput{1.0f};  // light: ∏ f cos / pdf alone, for Russian roulette
  float etaScale = 1.0f;
  int length = 0;  // edges so far
  bool specular = true;
  bool finiteLight = true;  // false after a directional light's or the sky's emission: no distance on its first edge
  float dVCM = 0, dVC = 0, dVM = 0;
  // Camera subpaths: dVC without the merge at the vertex last scattered from. When the path's
  // next vertex is on an emitter, that vertex is x₁, and without direct merges its merge is no
  // technique of the path (addEmission).
  float dVCNoMerge = 0;
  SampledWavelengths lambda;
};

// A diffuse or glossy vertex of a light subpath, kept for connections and merges.
struct VertexConnectionMerging::LightVertex {
  SurfaceHit hit;
  Vec3 wo;        // world, towards y_{s−2}: where the light came from
  Spectrum beta;  // flux arriving
  int length;     // edges from the light: the vertex is y_length, s = length + 1
  float dVCM, dVC, dVM;
  bool heroOnly;
  Vec3 woLocal;  // wo in the shading frame, and the geometric normal there: every connection
  Vec3 ngLocal;  // to this vertex needs both
};

// What merging needs of a light vertex, kept in the grid itself (photon/hash_grid.h).
struct MergeVertex {
  Vec3 p;
  Vec3 wo;
  Spectrum beta;
  float dVCM, dVM;
  int length;
  bool heroOnly;
};
using MergeGrid = HashGrid<MergeVertex>;

// Contributions, whole and (for --aov strategies) per technique.
struct Sink {
  Spectrum total{0.0f};
  std::vector<Spectrum>* perStrategy = nullptr;
  void add(int index, const Spectrum& v) {
    total += v;
    if (perStrategy) (*perStrategy)[size_t(index)] += v;
  }
};
struct SplatSink {
  SplatBuffer* all = nullptr;
  std::vector<SplatBuffer>* perStrategy = nullptr;  // one per technique
};

class VertexConnectionMerging::Tracer {
 public:
  Tracer(const Scene& scene, const BidirectionalOptions& o, const Iteration& it) : scene_(scene), o_(o), it_(it) {}

  float Mis(float ratio) const { return misTerm(ratio, o_.balanceHeuristic); }

  // Mis(η) for merging at the light vertex y_length, or 0 where that is no technique.
  float misVmAt(int lightLength) const { return o_.mergesAt(lightLength) ? it_.misVm : 0.0f; }

  // The weight of technique (s, t): its MIS weight, or under --only-s/--only-t 1 for that one
  // technique and 0 for the others.
  float weigh(int s, int t, float mis) const {
    if (o_.onlyS < 0) return mis;
    return s == o_.onlyS && t == o_.onlyT ? 1.0f : 0.0f;
  }

  // ----- light subpaths ----------------------------------------------------------------------

  void traceLightPath(Sampler& sampler, SampledWavelengths lambda, std::vector<LightVertex>* vertices, SplatSink& splat) const {
    const LightEmission emitted = emitLight(scene_, sampler, lambda);
    if (!emitted.light) return;
    const Light& light = *emitted.light;
    const EmittedRay& e = emitted.e;
    const float pick = emitted.pick;
    if (!(e.pdfPos * e.pdfDir > 0) || isBlack(e.flux) || !isFinite(e.flux)) return;
    // y₀: chosen by next-event estimation with area density directPdfA (a directional light's
    // direction is a delta: 1), emitted towards y₁ with emissionPdfW (tech. rep. eqs. 31–33, 48–50).
    // The sky is a direction, not a place: next-event estimation picks it with the solid-angle
    // density pdfDir, and the emitted ray starts on the bounding disc (pdfPos) with no cosine
    // there, as SmallVCM's background light.
    const bool infinite = light.isInfinite();
    const float directPdfA = pick * (light.isDeltaDirection() ? 1.0f : infinite ? e.pdfDir : e.pdfPos);
    const float emissionPdfW = pick * e.pdfPos * e.pdfDir;
    const float cosLight = light.isDeltaPosition() || infinite ? 1.0f : std::abs(glm::dot(e.n, e.ray.d));
    SubPath path;
    path.lambda = lambda;
    path.ray = e.ray;
    path.beta = e.flux / pick;
    path.finiteLight = !light.isDeltaDirection() && !infinite;
    path.dVCM = Mis(directPdfA / emissionPdfW);
    path.dVC = light.isDelta() ? 0.0f : Mis(cosLight / emissionPdfW);  // no ray hits a delta light: no s = 0
    path.dVM = path.dVC * it_.misVc;

    // The sky's emission point lies on the bounding disc, not on the sky: the camera cannot see it.
    if (o_.connect && !light.isDelta() && !infinite) emissionToCamera(light, e, pick, directPdfA, path.lambda, splat);

    if (o_.maxDepth < 1) return;

    // The walk (transport/light_walk.h): each diffuse or glossy vertex kept and connected to the
    // camera, the partial weights carried along.
    struct Walker {
      const Tracer& tracer;
      SubPath& path;
      std::vector<LightVertex>* vertices;
      SplatSink& splat;
      void attenuate(const Spectrum& transmittance) {  // roulette sees it too
        path.beta *= transmittance;
        path.throughput *= transmittance;
      }
      bool vertex(const SurfaceHit& hit, const Vec3& wo, int length) {
        path.length = length;
        // Complete the partial weights with this edge (eqs. 31–33): the distance and the cosine
        // at y turn the previous vertex's solid-angle densities into area densities at y. A
        // directional light's first edge has no distance: its y₁ density is pdfPos·cos.
        const float cosIn = std::abs(glm::dot(wo, hit.ng));
        if (path.length > 1 || path.finiteLight) path.dVCM *= tracer.Mis(hit.t * hit.t);
        path.dVCM /= tracer.Mis(cosIn);
        path.dVC /= tracer.Mis(cosIn);
        path.dVM /= tracer.Mis(cosIn);
        if (!hit.bsdf->isSpecular()) {
          LightVertex v{hit, wo, path.beta, path.length, path.dVCM, path.dVC, path.dVM, path.lambda.heroOnly,
                        hit.shading.toLocal(wo), hit.shading.toLocal(hit.ng)};
          if (tracer.o_.merge || tracer.o_.connect) vertices->push_back(v);
          if (tracer.o_.connect) tracer.connectToCamera(v, path.lambda, splat);  // t = 1
        }
        return path.length + 1 <= tracer.o_.maxDepth;
      }
      bool scattered(const SurfaceHit& hit, const LightScatter& s, int length, Sampler& sampler) {
        if (!tracer.advance(hit, s.woLocal, s.bc, s.bs, s.wi, path, tracer.o_.mergesAt(length)) || isBlack(path.beta))
          return false;
        // Russian roulette by throughput (core/roulette.h), on ∏ f cos / pdf, as the light tracer.
        if (length >= roulette::kFirstDepth) {
          const float q = roulette::throughput(maxComponent(path.throughput));
          if (!roulette::survives(q, [&] { return sampler.get1D(); })) return false;
          path.beta /= q;
          path.throughput /= q;
        }
        return isFinite(path.beta);
      }
    } walker{*this, path, vertices, splat};
    walkLightPath(scene_, path.ray, sampler, path.lambda, ShadingCheck::kEveryVertex, walker);
  }

  // (s, t) = (1, 1): the emission point y₀ seen by the camera, against the camera ray finding it
  // (s = 0, t = 2). Their densities, per pixel and per light path: camera N·p_cam,A(y₀)... as the
  // camera's importance is normalised over the image, its area density at y₀ per pixel is
  // W·H · pdf_dir · cos y₀ / d², and the light's is N · directPdfA.
  void emissionToCamera(const Light& light, const EmittedRay& e, float pick, float directPdfA,
                        const SampledWavelengths& lambda, SplatSink& splat) const {
    CameraSample cs;
    const Camera& camera = scene_.camera();
    if (!camera.sampleWi(e.ray.o, it_.width, it_.height, scene_.cameraTanHalf(), &cs)) return;
    Spectrum Le = light.L(e.ray.o, cs.wi, lambda);
    if (isBlack(Le)) return;
    const float cosY = std::abs(glm::dot(e.n, cs.wi));
    const float cameraPdfA = cameraAreaPdf(cs, cosY);
    const float w = weigh(1, 1, 1.0f / (1.0f + Mis(cameraPdfA / (it_.lightPaths * directPdfA))));
    if (w == 0) return;
    SurfaceHit y;
    y.p = e.ray.o;
    y.ng = e.n;
    if (!scene_.visible(y, cs.wi, cs.distance)) return;
    addSplat(splat, 1, 1, cs.raster, Le * (w * cosY * cs.We / (pick * e.pdfPos * cs.pdf)), lambda);
  }

  // (s, t) = (length + 1, 1): light tracing. The camera's per-pixel area density of having
  // made this vertex, over N light paths, against everything the light subpath holds (eq. 46).
  void connectToCamera(const LightVertex& v, const SampledWavelengths& lambda, SplatSink& splat) const {
    const SurfaceHit& hit = v.hit;
    CameraSample cs;
    if (!scene_.camera().sampleWi(hit.p, it_.width, it_.height, scene_.cameraTanHalf(), &cs)) return;
    const Vec3& woLocal = v.woLocal;
    const Vec3 wiLocal = hit.shading.toLocal(cs.wi);
    if (!sidesAgree(hit, v.wo, cs.wi, woLocal, wiLocal)) return;
    const BSDFContext bc = bsdfContext(hit, lambda, TransportMode::Importance);
    const BSDFEval e = hit.bsdf->evaluate(woLocal, wiLocal, bc, true);
    Spectrum f = e.f * shadingNormalCorrection(woLocal, wiLocal, v.ngLocal, TransportMode::Importance);
    if (isBlack(f)) return;
    const float cameraPdfA = cameraAreaPdf(cs, std::abs(glm::dot(cs.wi, hit.ng)));
    const float revPdf = e.pdfReverse;
    const float wLight = Mis(cameraPdfA / it_.lightPaths) * (misVmAt(v.length) + v.dVCM + v.dVC * Mis(revPdf));
    const int s = v.length + 1;
    const float w = weigh(s, 1, 1.0f / (wLight + 1.0f));
    if (w == 0 || !scene_.visible(hit, cs.wi, cs.distance)) return;
    addSplat(splat, s, 1, cs.raster, v.beta * f * (w * std::abs(wiLocal.z) * cs.We / cs.pdf), lambda);
  }

  // ----- camera subpaths ---------------------------------------------------------------------

  // A camera path; connects to the light vertices [lights, lightsEnd) (the light subpath of the
  // same index), merges with every light vertex through the grid.
  void traceCameraPath(Sampler& sampler, const Ray& cameraRay, const SampledWavelengths& lambda, const LightVertex* lights,
                       const LightVertex* lightsEnd, const MergeGrid* grid, Sink& sink) const {
    SubPath path;
    path.lambda = lambda;
    path.ray = cameraRay;
    // z₁'s density, per pixel: W·H · pdf_dir (the camera's is normalised over the image); its
    // ratio to the N light paths that could splat it (eq. 31).
    const float pdfDir = scene_.camera().generatedPdfDir(path.ray.d, it_.width, it_.height, scene_.cameraTanHalf());
    path.dVCM = Mis(it_.lightPaths / (it_.pixels * pdfDir));
    for (path.length = 1;; ++path.length) {
      SurfaceHit hit;
      if (!scene_.intersect(path.ray, &hit)) {
        if (scene_.environment()) background(path, sink);  // s = 0, t = length + 1
        return;
      }
      {  // Beer–Lambert through an absorbing volume the edge crossed; roulette sees it too
        const Spectrum transmittance = scene_.transmittance(hit, path.ray.d, path.lambda);
        path.beta *= transmittance;
        path.throughput *= transmittance;
      }
      const Vec3 wo = -path.ray.d;
      const float cosIn = std::abs(glm::dot(wo, hit.ng));
      path.dVCM *= Mis(hit.t * hit.t);
      path.dVCM /= Mis(cosIn);
      path.dVC /= Mis(cosIn);
      path.dVCNoMerge /= Mis(cosIn);
      path.dVM /= Mis(cosIn);

      if (hit.light) emission(hit, wo, path, sink);  // s = 0, t = length + 1
      if (path.length > o_.maxDepth) return;          // no technique from here is short enough

      if (!hit.bsdf->isSpecular()) {
        const Vec3 woLocal = hit.shading.toLocal(wo);
        if (o_.connect) {
          directIllumination(hit, woLocal, path, sampler, sink);  // s = 1
          const Vec3 woShading = hit.shading.toWorld(woLocal);  // wo as the connections see it
          for (const LightVertex* l = lights; l < lightsEnd; ++l) {
            const LightVertex& v = *l;
            if (v.length + 1 + path.length > o_.maxDepth + 1) break;  // stored in order of length
            connect(hit, woShading, woLocal, path, v, sink);
          }
        }
        if (o_.merge && grid) merge(hit, woLocal, path, *grid, sink);
      }
      if (!scatter(hit, wo, sampler, path, true)) return;
      // Russian roulette by throughput (core/roulette.h), as the path tracer (the camera's
      // vertex counts in the length: length 4 is the path tracer's depth 3).
      if (path.length >= roulette::kFirstDepth + 1) {
        const float q = roulette::throughput(maxComponent(path.beta), path.etaScale);
        if (!roulette::survives(q, [&] { return sampler.get1D(); })) return;
        path.beta /= q;
      }
    }
  }

  // s = 0: the camera path found an emitter. Its rivals: next-event estimation at this point
  // (directPdfA) and the light subpath emitting towards the previous camera vertex (emissionPdfW),
  // then everything further back (eqs. 42–43). bpm has neither: it keeps only the paths that
  // nothing can merge, the purely specular ones.
  void emission(const SurfaceHit& hit, const Vec3& wo, const SubPath& path, Sink& sink) const {
    Spectrum Le = hit.light->L(hit.uv, wo, path.lambda);
    if (isBlack(Le)) return;
    float pdfPos = 0, pdfDir = 0;
    if (o_.connect) hit.light->pdfLe(Ray{hit.p, wo}, hit.ng, &pdfPos, &pdfDir);
    addEmission(Le, scene_.lightDistribution().pmf(size_t(hit.lightIndex)), pdfPos, pdfPos, pdfDir, false, path, sink);
  }

  // s = 0 with the sky: the camera ray left the scene. Its rivals as an emitter's, in the sky's
  // measures (SmallVCM's background light): next-event estimation picks the direction with
  // solid-angle density pick·p(ω), and the path's partial sums are still in solid angle at the
  // last vertex (no hit completed them); emission starts on the bounding disc, cosine 1. Seen
  // directly it is the only technique: no light path reaches the camera from the sky (no (1, 1)).
  void background(const SubPath& path, Sink& sink) const {
    const EnvironmentLight& sky = *scene_.environment();
    const Vec3 d = path.ray.d;
    Spectrum Le = sky.radiance(d, path.lambda);
    if (isBlack(Le)) return;
    float pdfPos = 0, pdfDir = 0;
    if (o_.connect) sky.pdfLe(Ray{path.ray.o, -d}, Vec3(0.0f), &pdfPos, &pdfDir);
    addEmission(Le, scene_.lightDistribution().pmf(size_t(scene_.environmentIndex())), pdfDir, pdfPos, pdfDir,
                path.length == 1, path, sink);
  }

  // Emission Le found by the camera path (s = 0, t = length + 1), weighed against next-event
  // estimation choosing the emitter's point (or the sky's direction) with density pick·directPdf
  // and the light subpath emitting it with pick·pdfPos·pdfDir (eqs. 42–43); `alone`: no other
  // technique makes this path.
  void addEmission(const Spectrum& Le, float pick, float directPdf, float pdfPos, float pdfDir, bool alone,
                   const SubPath& path, Sink& sink) const {
    float mis;
    if (alone) {
      mis = 1.0f;
    } else if (o_.connect) {
      const float directPdfA = pick * directPdf, emissionPdfW = pick * pdfPos * pdfDir;
      mis = 1.0f / (1.0f + Mis(directPdfA) * path.dVCM + Mis(emissionPdfW) * (o_.directMerges ? path.dVC : path.dVCNoMerge));
    } else {
      mis = path.specular ? 1.0f : 0.0f;
    }
    const int t = path.length + 1;
    const float w = weigh(0, t, mis);
    if (w != 0) sink.add(strategyIndex(0, t), path.beta * Le * w);
  }

  // s = 1: next-event estimation. Rivals: the BSDF sampling the light (wLight; never a delta
  // light), and the light subpath of one more vertex with everything further back (wCamera,
  // eqs. 44–45). The latter's first factor is the density of y₀ emitting towards z over the
  // density of choosing y₀: pdfDir·cos z/d², or pdfPos·cos z for a directional light.
  void directIllumination(const SurfaceHit& hit, const Vec3& woLocal, const SubPath& path, Sampler& sampler, Sink& sink) const {
    const AliasTable& lights = scene_.lightDistribution();
    if (lights.size() == 0 || lights.total() <= 0) return;
    float pick;
    const Light& light = *scene_.lights()[lights.sample(sampler.get1D(), &pick)];
    const Vec2 u = sampler.get2D();
    LightSample ls;
    if (!light.sampleLi(hit.p, u, path.lambda, &ls)) return;
    const Vec3 wo = hit.shading.toWorld(woLocal);
    const Vec3 wiLocal = hit.shading.toLocal(ls.wi);
    if (!sidesAgree(hit, wo, ls.wi, woLocal, wiLocal)) return;
    const BSDFContext bc = bsdfContext(hit, path.lambda);
    const BSDFEval e = hit.bsdf->evaluate(woLocal, wiLocal, bc, true);
    const Spectrum& f = e.f;
    if (isBlack(f)) return;
    const float cosZ = std::abs(glm::dot(ls.wi, hit.ng));
    const Vec3 y = std::isinf(ls.distance) ? hit.p : hit.p + ls.wi * ls.distance;
    float pdfPos, pdfDir;
    light.pdfLe(Ray{y, -ls.wi}, Vec3(0.0f), &pdfPos, &pdfDir);
    // Emission over next-event estimation, emissionPdfW·cos z/(directPdfW·cos y): pdfDir·cos z/d²
    // for a light at a place; pdfPos·cos z for a direction (directional light, the sky: no
    // distance, no cosine at the light).
    const float emissionRatio = light.isDeltaDirection() || light.isInfinite() ? pdfPos * cosZ
                                                                               : pdfDir * cosZ / (ls.distance * ls.distance);
    const float bsdfDirPdf = light.isDelta() ? 0.0f : e.pdf;
    const float bsdfRevPdf = e.pdfReverse;
    const float wLight = Mis(bsdfDirPdf / (pick * ls.pdf));
    const float wCamera = Mis(emissionRatio) * (misVmAt(1) + path.dVCM + path.dVC * Mis(bsdfRevPdf));
    const int t = path.length + 1;
    const float w = weigh(1, t, 1.0f / (wLight + 1.0f + wCamera));
    if (w == 0 || !scene_.visible(hit, ls.wi, ls.distance)) return;
    sink.add(strategyIndex(1, t), path.beta * f * ls.Li * (w * std::abs(wiLocal.z) / (pick * ls.pdf)));
  }

  // s, t ≥ 2: connect z (camera) to y (light vertex). Each side's density of having made the
  // other's vertex, in area measure, scales that side's running sums (eqs. 40–41).
  // wo: hit.shading.toWorld(woLocal), made once for all the light vertices.
  void connect(const SurfaceHit& hit, const Vec3& wo, const Vec3& woLocal, const SubPath& path, const LightVertex& v,
               Sink& sink) const {
    Vec3 d = v.hit.p - hit.p;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0)) return;
    const float dist = std::sqrt(dist2);
    d /= dist;
    // Through a surface only where its BSDF transmits (the test first: it spares the rest).
    if (glm::dot(d, hit.ng) * glm::dot(wo, hit.ng) <= 0 && !hasSmoothTransmission(hit.bsdf->flags())) return;
    if (glm::dot(-d, v.hit.ng) * glm::dot(v.wo, v.hit.ng) <= 0 && !hasSmoothTransmission(v.hit.bsdf->flags())) return;
    const Vec3 wiLocal = hit.shading.toLocal(d);
    const Vec3& lightWo = v.woLocal;
    const Vec3 lightWi = v.hit.shading.toLocal(-d);
    if (!sidesAgree(hit, wo, d, woLocal, wiLocal) || !sidesAgree(v.hit, v.wo, -d, lightWo, lightWi)) return;
    const BSDFContext cc = bsdfContext(hit, path.lambda);
    const BSDFEval camera = hit.bsdf->evaluate(woLocal, wiLocal, cc, true);
    const Spectrum& fCamera = camera.f;
    if (isBlack(fCamera)) return;
    const BSDFContext lc = bsdfContext(v.hit, path.lambda, TransportMode::Importance);
    const BSDFEval light = v.hit.bsdf->evaluate(lightWo, lightWi, lc, true);
    Spectrum fLight = light.f * shadingNormalCorrection(lightWo, lightWi, v.ngLocal, TransportMode::Importance);
    if (isBlack(fLight)) return;
    const float cosCamera = std::abs(glm::dot(d, hit.ng)), cosLight = std::abs(glm::dot(d, v.hit.ng));
    const float cameraDirPdfA = camera.pdf * cosLight / dist2;
    const float cameraRevPdf = camera.pdfReverse;
    const float lightDirPdfA = light.pdf * cosCamera / dist2;
    const float lightRevPdf = light.pdfReverse;
    const float wLight = Mis(cameraDirPdfA) * (misVmAt(v.length) + v.dVCM + v.dVC * Mis(lightRevPdf));
    const float wCamera = Mis(lightDirPdfA) * (it_.misVm + path.dVCM + path.dVC * Mis(cameraRevPdf));
    const int s = v.length + 1, t = path.length + 1;
    float w = weigh(s, t, 1.0f / (wLight + 1.0f + wCamera));
    if (w == 0) return;
    if (path.lambda.heroOnly && v.heroOnly) w /= kWavelengths;
    // G with the shading cosines (the BSDFs' own), the geometric ones only in the densities.
    const float G = std::abs(wiLocal.z) * std::abs(lightWi.z) / dist2;
    if (!scene_.visible(hit, d, dist)) return;
    sink.add(strategyIndex(s, t), path.beta * fCamera * fLight * v.beta * (w * G));
  }

  // Merging at z: the photon-map estimate Σ f(z, ωy) Φy / (N πr²) over the light vertices within
  // r, each weighed against connecting at either end and merging elsewhere (eqs. 37–39).
  void merge(const SurfaceHit& hit, const Vec3& woLocal, const SubPath& path, const MergeGrid& grid, Sink& sink) const {
    const Vec3 wo = hit.shading.toWorld(woLocal);
    const BSDFContext cc = bsdfContext(hit, path.lambda);
    const bool shadingDiffers = hit.shadingDiffers();
    const bool transmits = hasSmoothTransmission(hit.bsdf->flags());
    const Vec3 ngLocal = hit.shading.toLocal(hit.ng);
    Spectrum sum(0.0f);
    grid.query(hit.p, [&](const MergeVertex& v) {
      if (v.length + path.length > o_.maxDepth + 1) return;
      // From the other side of the surface only where the BSDF transmits.
      if (glm::dot(v.wo, hit.ng) * glm::dot(wo, hit.ng) <= 0 && !transmits) return;
      const Vec3 wiLocal = hit.shading.toLocal(v.wo);
      if (transmits && !sidesAgree(hit, wo, v.wo, woLocal, wiLocal)) return;
      const BSDFEval e = hit.bsdf->evaluate(woLocal, wiLocal, cc, true);
      Spectrum f = e.f;
      if (shadingDiffers) f *= densityShadingCorrection(wiLocal, ngLocal);
      if (isBlack(f)) return;
      const float cameraDirPdf = e.pdf;
      const float cameraRevPdf = e.pdfReverse;
      const float wLight = v.dVCM * it_.misVc + v.dVM * Mis(cameraDirPdf);
      const float wCamera = path.dVCM * it_.misVc + path.dVM * Mis(cameraRevPdf);
      float w = 1.0f / (wLight + 1.0f + wCamera);
      if (path.lambda.heroOnly && v.heroOnly) w /= kWavelengths;
      sum += f * v.beta * w;
    });
    if (!isBlack(sum)) sink.add(-1, path.beta * sum * it_.vmNormalization);
  }

  // ----- shared --------------------------------------------------------------------------------

  // Samples a camera subpath's next direction (the light subpath's walk samples its own:
  // transport/light_walk.h) and updates the partial weights for it (advance, eqs. 34–36): the new
  // vertex's dVCM is 1/pdf_dir (its area form is completed at the next hit); dVC and dVM gather
  // the reverse density of the edge just walked. A delta lobe has equal forward and reverse
  // densities and no connection or merge at its vertex: dVCM = 0, and the others only change
  // measure.
  // mergeHere: merging at this vertex is a technique (BidirectionalOptions::mergesAt).
  bool scatter(const SurfaceHit& hit, const Vec3& wo, Sampler& sampler, SubPath& path, bool mergeHere) const {
    LightScatter s;
    if (!scatterBSDF(hit, wo, sampler, path.lambda, TransportMode::Radiance, ShadingCheck::kEveryVertex, &s)) return false;
    if (!advance(hit, s.woLocal, s.bc, s.bs, s.wi, path, mergeHere)) return false;
    path.ray = scene_.spawnRay(hit, s.wi);
    return !isBlack(path.beta);
  }

  // The partial weights and the throughput after a scattering at `hit` towards wi, sampled as
  // `bs` (its weight with the shading-normal correction where the subpath needs it). False: a
  // direction no technique could have sampled.
  bool advance(const SurfaceHit& hit, const Vec3& woLocal, const BSDFContext& bc, const BSDFSample& bs, const Vec3& wi,
               SubPath& path, bool mergeHere) const {
    const float cosOut = std::abs(glm::dot(wi, hit.ng));
    if (bs.delta) {
      path.dVCM = 0.0f;
      path.dVC *= Mis(cosOut);
      path.dVCNoMerge = path.dVC;  // no merge at a delta vertex
      path.dVM *= Mis(cosOut);
    } else {
      if (!(bs.pdf > 0)) return false;
      const float revPdf = hit.bsdf->pdf(bs.wi, woLocal, bc);
      // This vertex's own terms: dVCM for connecting here, and merging here (misVm in dVC's
      // units, 1 in dVM's) where that is a technique.
      const float dVCBefore = path.dVC * Mis(revPdf) + path.dVCM;
      path.dVC = Mis(cosOut / bs.pdf) * (dVCBefore + (mergeHere ? it_.misVm : 0.0f));
      path.dVCNoMerge = Mis(cosOut / bs.pdf) * dVCBefore;
      path.dVM = Mis(cosOut / bs.pdf) * (path.dVM * Mis(revPdf) + path.dVCM * it_.misVc + (mergeHere ? 1.0f : 0.0f));
      path.dVCM = Mis(1.0f / bs.pdf);
    }
    path.beta *= bs.weight;
    path.throughput *= bs.weight;
    path.etaScale *= bs.eta * bs.eta;
    path.specular = path.specular && bs.delta;
    return true;
  }

 private:
  // The camera's area density at a scene point, per pixel (its importance is normalised over
  // the image, so per pixel it is W·H times the image's): W·H · pdf_dir · cos / d².
  float cameraAreaPdf(const CameraSample& cs, float cosAtPoint) const {
    return it_.pixels * cs.pdfDir * cosAtPoint / (cs.distance * cs.distance);
  }
  void addSplat(SplatSink& splat, int s, int t, const Vec2& raster, const Spectrum& v,
                const SampledWavelengths& lambda) const {
    Spectrum rgb = lambda.spectral ? spectralToRGB(v, lambda.lambda) : v;
    splat.all->add(raster, it_.width, rgb);
    if (splat.perStrategy) (*splat.perStrategy)[size_t(strategyIndex(s, t))].add(raster, it_.width, rgb);
  }

  const Scene& scene_;
  const BidirectionalOptions& o_;
  const Iteration& it_;
};

// ---------------------------------------------------------------------------------------------
// The loop: iteration i traces N = W·H light subpaths (chunks in parallel, vertices and splats
// kept per chunk, splats added in chunk order), builds the grid over their vertices (merging), then
// one camera subpath per pixel; bdpt, which has no grid, traces each chunk's camera paths right
// after its light paths. Random streams are keyed by (seed, path or pixel, iteration),
// so the image is the same whatever the thread count. An iteration the budget cuts short is
// dropped whole.
ImageRGB VertexConnectionMerging::render(const Scene& scene, const RenderOptions& options, RenderInfo* info) {
  const int strategies = o_.strategies ? strategyCount(o_.maxDepth) : 0;
  RenderSession session(scene, options, (6 + 3 * uint64_t(strategies)) * sizeof(double) + 3 * sizeof(float), "film");
  const RenderOptions& o = session.options();
  const int W = session.width, H = session.height, threads = session.threads;
  const size_t pixels = session.pixels;
  const Budget& budget = session.budget;
  const uint64_t lightStream = mix64(o.seed ^ 0x76636d6c69676874ULL);  // "vcmlight"
  const uint64_t lambdaStream = mix64(o.seed ^ 0x7663636c616d6264ULL);
  const uint64_t cameraStream = mix64(o.seed ^ 0x7663636d63616d65ULL);  // --sampler sobol's camera sequences

  std::vector<ExactSum> cameraSum(pixels * 3);  // exact: slices of a render add up to its bits
  std::vector<Spectrum> iterationColor(pixels);
  std::vector<double> strategySum(size_t(strategies) * pixels * 3, 0.0);
  std::vector<Spectrum> iterationStrategies(size_t(strategies) * pixels);
  SplatFilm splatTotal(W, H);
  std::vector<SplatFilm> strategySplats(size_t(strategies), SplatFilm(W, H));
  const size_t chunkSize = 4096, chunks = (pixels + chunkSize - 1) / chunkSize;
  std::vector<std::vector<LightVertex>> chunkVertices(chunks);
  std::vector<std::vector<uint32_t>> chunkEnds(chunks);  // per path: one past its last vertex, in the chunk
  std::vector<SplatBuffer> chunkSplats(chunks);
  std::vector<std::vector<SplatBuffer>> chunkStrategySplats(o_.strategies ? chunks : 0);
  MergeGrid grid;
  std::vector<MergeVertex> mergeVertices;

  // Without a radius (an integrator made outside the CLI's resolve step): the default.
  const float radius1 =
      o_.radius > 0 ? o_.radius : (o_.merge ? mergeFootprints(o_.directMerges) * defaultRadius(scene, W, H).footprint : 0.0f);
  int done = 0;
  float radius = radius1;
  uint64_t nonFinite = 0;
  auto infoAt = [&](bool last) {
    RenderInfo st = session.info(last);
    st.spp = done;
    st.meanWork = done;
    st.photons = uint64_t(done) * pixels;
    st.meanRadius = o_.merge ? radius : 0.0;
    st.nonFiniteSamples = nonFinite + splatTotal.nonFinite();
    return st;
  };
  auto estimate = [&] {
    ImageRGB image = splatTotal.image(done > 0 ? 1.0 / done : 0.0);
    for (size_t i = 0; i < pixels * 3; ++i) image.data[i] += done > 0 ? pixelMean(cameraSum[i], uint32_t(done)) : 0.0f;
    return image;
  };

  RenderOptions rgbImage = o;  // camera rays as the per-pixel loop's; wavelengths drawn here
  rgbImage.spectral = false;
  rgbImage.checkpoint = nullptr;

  // A slice (--sample-range A:B:K) runs iterations A, A + K, ... below B, each keyed (light
  // paths, wavelengths, radius) as in the whole render.
  if (o.sliced() && o_.strategies) throw Error("--aov strategies: not with a slice of the render");
  auto runIteration = [&](int iteration) {
    Iteration it;
    it.width = W, it.height = H;
    it.pixels = float(pixels);
    it.lightPaths = float(pixels);
    // r_i = r₁ · i^((α−1)/2) (Knaus & Zwicker 2011), i from 1.
    radius = std::max(1e-7f, radius1 * std::pow(float(iteration + 1), 0.5f * (o_.alpha - 1.0f)));
    it.radius = radius;
    const float eta = it.lightPaths * kPi * radius * radius;
    it.misVm = o_.merge ? misTerm(eta, o_.balanceHeuristic) : 0.0f;
    it.misVc = o_.connect ? misTerm(1.0f / eta, o_.balanceHeuristic) : 0.0f;
    it.vmNormalization = 1.0f / eta;
    Tracer tracer(scene, o_, it);
    // Wavelengths: a merge joins paths of different pixels, so with merging the whole
    // iteration shares one set, and the iterations' sets follow a randomly shifted Kronecker
    // sequence (u_i = u₀ + i/φ mod 1), uniform for each iteration and stratified across them,
    // so that few iterations already cover the spectrum; bdpt pairs light path i with pixel i
    // and gives each pair its own.
    const double uIteration = std::fmod(Rng::keyed(lambdaStream, 0, 0).uniform() + 0.6180339887498949 * iteration, 1.0);
    auto wavelengths = [&](uint64_t path) {
      if (!o.spectral) return SampledWavelengths();
      if (o_.merge) return SampledWavelengths::sample(std::min(float(uIteration), 0.99999994f));
      return SampledWavelengths::sample(Rng::keyed(lambdaStream, path, uint64_t(iteration)).uniform());
    };

    // 1. Light subpaths, chunk k's: paths (and pixels) [k·chunkSize, (k + 1)·chunkSize). Returns
    // false when the budget ran out first.
    std::atomic<bool> cut{false};
    std::vector<uint64_t> chunkNonFinite(chunks, 0);
    auto lightPaths = [&](size_t k) {
      std::vector<LightVertex>& verts = chunkVertices[k];
      std::vector<uint32_t>& ends = chunkEnds[k];
      verts.clear();
      ends.clear();
      chunkSplats[k].clear();
      if (o_.strategies) chunkStrategySplats[k].assign(size_t(strategies), SplatBuffer());
      if (cut || budget.expired()) {
        cut = true;
        return false;
      }
      SplatSink sink{&chunkSplats[k], o_.strategies ? &chunkStrategySplats[k] : nullptr};
      const size_t begin = k * chunkSize, end = std::min(pixels, begin + chunkSize);
      for (size_t i = begin; i < end; ++i) {
        Rng rng = Rng::keyed(lightStream, i, uint64_t(iteration));
        Sampler sampler(rng, o_.sobol, mix64(lightStream ^ i), uint32_t(iteration), kSamplerSlots);
        tracer.traceLightPath(sampler, wavelengths(i), &verts, sink);
        ends.push_back(uint32_t(verts.size()));
      }
      return true;
    };

    // 3 (below). The camera subpath of one pixel: connects to the light path of the same index,
    // merges through the grid. `perStrategy`: the caller's scratch, one entry per technique.
    auto cameraPath = [&](size_t pixel, std::vector<Spectrum>& perStrategy, uint64_t& nonFiniteHere) {
      const int x = int(pixel % size_t(W)), y = int(pixel / size_t(W));
      CameraPath c = beginCameraPath(scene, rgbImage, x, y, uint64_t(iteration));
      c.lambda = wavelengths(pixel);
      std::fill(perStrategy.begin(), perStrategy.end(), Spectrum(0.0f));
      Sink sink;
      sink.perStrategy = o_.strategies ? &perStrategy : nullptr;
      // Light path `pixel`: in chunk pixel / chunkSize, after the vertices of the paths before it there.
      const std::vector<LightVertex>& chunk = chunkVertices[pixel / chunkSize];
      const std::vector<uint32_t>& ends = chunkEnds[pixel / chunkSize];
      const size_t j = pixel % chunkSize;
      const LightVertex* first = chunk.data() + (j == 0 ? 0 : ends[j - 1]);
      Sampler sampler(c.rng, o_.sobol, mix64(cameraStream ^ pixel), uint32_t(iteration), kSamplerSlots);
      jitterFromSampler(scene, x, y, W, H, sampler, &c.ray);
      tracer.traceCameraPath(sampler, c.ray, c.lambda, first, chunk.data() + ends[j], o_.merge ? &grid : nullptr, sink);
      auto toRGB = [&](const Spectrum& v) { return o.spectral ? spectralToRGB(v, c.lambda.lambda) : v; };
      Spectrum rgb = toRGB(sink.total);
      if (!isFinite(rgb)) {
        ++nonFiniteHere;
        rgb = Spectrum(0.0f);
      }
      iterationColor[pixel] = rgb;
      for (int i = 0; i < strategies; ++i) {
        Spectrum v = toRGB(perStrategy[size_t(i)]);
        iterationStrategies[size_t(i) * pixels + pixel] = isFinite(v) ? v : Spectrum(0.0f);
      }
    };

    // 1 and, for bdpt, 3: the chunks' light paths in parallel. A bdpt camera path needs only the
    // light path of its own index, so there each chunk goes on to its pixels' camera paths while
    // its light vertices are still in cache (bit for bit what a separate pass would give); vcm
    // and bpm must build the grid over every chunk's vertices first (2, then 3).
    parallelFor(chunks, threads, [&](size_t k, int) {
      if (!lightPaths(k) || o_.merge) return;
      std::vector<Spectrum> perStrategy(static_cast<size_t>(strategies));
      for (size_t i = k * chunkSize, end = std::min(pixels, i + chunkSize); i < end; ++i)
        cameraPath(i, perStrategy, chunkNonFinite[k]);
    });
    if (cut) return false;  // the iteration is dropped whole

    // 2. The grid over every stored light vertex.
    if (o_.merge) {
      mergeVertices.clear();
      // Vertices no merge uses (y₁ without direct merges) are left out of the grid.
      for (const std::vector<LightVertex>& chunk : chunkVertices)
        for (const LightVertex& v : chunk)
          if (o_.mergesAt(v.length)) mergeVertices.push_back({v.hit.p, v.wo, v.beta, v.dVCM, v.dVM, v.length, v.heroOnly});
      grid.build(mergeVertices, radius);
    }

    // 3. Camera subpaths, one per pixel, rows in parallel (bdpt traced them above).
    std::vector<uint64_t> rowNonFinite(o_.merge ? size_t(H) : 0, 0);
    if (o_.merge) {
      parallelFor(size_t(H), threads, [&](size_t y, int) {
        if (cut || budget.expired()) {
          cut = true;
          return;
        }
        std::vector<Spectrum> perStrategy(static_cast<size_t>(strategies));
        for (size_t i = y * size_t(W), end = i + size_t(W); i < end; ++i) cameraPath(i, perStrategy, rowNonFinite[y]);
      });
      if (cut) return false;
    }

    // The iteration is complete: into the exact sums, in parallel (exact, so bit for bit the
    // serial order's), the light-side splats straight into the total.
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (size_t i = y * size_t(W), end = i + size_t(W); i < end; ++i)
        for (int ch = 0; ch < 3; ++ch) cameraSum[i * 3 + size_t(ch)].add(iterationColor[i][ch]);
    });
    for (uint64_t n : rowNonFinite) nonFinite += n;
    for (uint64_t n : chunkNonFinite) nonFinite += n;
    splatTotal.add(chunkSplats, threads);
    for (int s = 0; s < strategies; ++s) {
      for (size_t i = 0; i < pixels; ++i)
        for (int ch = 0; ch < 3; ++ch)
          strategySum[(size_t(s) * pixels + i) * 3 + size_t(ch)] += iterationStrategies[size_t(s) * pixels + i][ch];
      for (size_t k = 0; k < chunks; ++k) strategySplats[size_t(s)].add(std::vector<SplatBuffer>{chunkStrategySplats[k][size_t(s)]});
    }
    ++done;
    return true;
  };
  session.run(session.units(unitTarget(o.spp, o.timeLimit)), runIteration, infoAt, estimate);
  if (info) {
    *info = infoAt(true);
    if (o.sliced()) {
      info->slice = makeSlice(o, W, H, std::move(cameraSum), splatTotal.sums(), std::vector<uint32_t>(pixels, uint32_t(done)));
      return info->slice->mean();
    }
  }

  strategyImages_.clear();
  for (int k = 0; k <= o_.maxDepth && o_.strategies; ++k)
    for (int s = 0; s <= k + 1; ++s) {
      const int t = k + 2 - s, index = strategyIndex(s, t);
      ImageRGB image = strategySplats[size_t(index)].image(done > 0 ? 1.0 / done : 0.0);
      for (size_t i = 0; i < pixels * 3; ++i)
        image.data[i] += done > 0 ? float(strategySum[size_t(index) * pixels * 3 + i] / done) : 0.0f;
      strategyImages_.push_back({"s" + std::to_string(s) + "t" + std::to_string(t), std::move(image)});
    }
  return estimate();
}

// ---------------------------------------------------------------------------------------------
// Registration: the three algorithms and their parameters.
namespace {

ParamSpec iterations() {
  ParamSpec s = params::spp();
  s.doc = "iterations: each traces W·H light subpaths and one camera subpath per pixel";
  return s;
}

ParamSpec mergeAlpha() {
  ParamSpec s = params::alpha();
  s.doc = "radius reduction: r_i = r_1 · i^((alpha-1)/2)";
  s.defaultValue = "0.75";
  s.defaultDoc = "0.75";
  return s;
}

ParamSpec mergeRadius(const char* defaultDoc) {
  ParamSpec s = params::progressiveRadius();
  s.doc = "initial merge radius r_1 in metres";
  s.defaultDoc = defaultDoc;
  return s;
}

// The merge radius, in pixel footprints at the median visible distance (mergeFootprints).
std::string resolveMergeRadius(const Scene& scene, int width, int height, ParamSet& params) {
  if (params.isSet("radius")) return "initial merge radius " + formatNumber(float(params.real("radius"))) + " m";
  // bpm declares no direct_merges: it merges at every vertex, x₁ included.
  const bool directMerges = !params.has("direct_merges") || params.choice("direct_merges") == "on";
  const float footprints = mergeFootprints(directMerges);
  DefaultRadius r = defaultRadius(scene, width, height);
  params.resolve("radius", footprints * r.footprint);
  return "initial merge radius " + formatNumber(footprints * r.footprint) + " m (default: " + formatNumber(footprints) +
         " pixel footprint" + (footprints == 1 ? "" : "s") + " at the median visible distance " + formatNumber(r.distance) + " m)";
}

BidirectionalOptions common(const ParamSet& p) {
  BidirectionalOptions o;
  o.maxDepth = int(p.integer("max_depth"));
  if (p.has("radius")) o.radius = float(p.real("radius"));
  if (p.has("alpha")) o.alpha = float(p.real("alpha"));
  o.balanceHeuristic = p.choice("heuristic") == "balance";
  o.sobol = p.choice("sampler") == "sobol";
  return o;
}

ParamSpec heuristic() {
  return params::choice("heuristic",
                        "the MIS weights: power (beta = 2, Veach 1997) or balance (beta = 1, as SmallVCM and pbrt-v3's bdpt)",
                        "power", {"power", "balance"});
}

// vcm: whether light vertices one edge from the light ("direct photons") are merged.
ParamSpec directMerges() {
  return params::choice("direct_merges",
                        "off: no merging at x1, the first vertex after the light (next-event estimation and light tracing "
                        "carry that light, unmerged); on: every merge, as Georgiev et al. 2012",
                        "off", {"on", "off"});
}

// All three draw from Sobol' points by default: at equal iterations they lowered the error of
// the best 99% of pixels on each of the four shipped scenes measured, for little time (docs:
// explanation/bidirectional.md, "Sampler"). --sampler independent gives the random stream alone.
ParamSpec sampler() {
  return params::sampler(kSamplerSlots, "subpath", "the iterations, per pixel and per light path", "sobol");
}

ParamSpec strategyAov() {
  return params::choice("aov", "strategies: also write OUT.s<S>t<T>.ext, each technique's weighted share (they sum to the image)",
                        "radiance", {"radiance", "strategies"});
}

ParamSpec onlyStrategy(const char* name, const char* doc) {
  ParamSpec s{name, ParamType::Integer, doc};
  s.defaultDoc = "every technique, weighted";
  s.lo = 0, s.hi = 64;
  return s;
}

}  // namespace

IntegratorEntry bdptEntry() {
  return IntegratorEntry(
      "bdpt", "bidirectional path tracing (Veach 1997): every connection (s, t), power- or balance-heuristic MIS",
      IntegratorFamily::Own, "spp",
      {iterations(), params::maxDepth(), heuristic(), sampler(), strategyAov(),
       onlyStrategy("only_s", "debug: render technique (s, t) alone, unweighted: its light vertices s (with only_t)"),
       onlyStrategy("only_t", "debug: its camera vertices t, the pinhole included (with only_s)")},
      [](const ParamSet& p, const RenderOptions&) {
        BidirectionalOptions o = common(p);
        o.strategies = p.choice("aov") == "strategies";
        if (p.isSet("only_s") != p.isSet("only_t")) throw Error("--only-s and --only-t go together");
        if (p.isSet("only_s")) {
          o.onlyS = int(p.integer("only_s"));
          o.onlyT = int(p.integer("only_t"));
          if (o.onlyT < 1) throw Error("--only-t: a technique has at least the camera's vertex, t >= 1");
        }
        return std::make_unique<VertexConnectionMerging>(o, "bdpt");
      });
}

IntegratorEntry bpmEntry() {
  return IntegratorEntry(
      "bpm", "bidirectional photon mapping (Vorba 2011): merging at every camera vertex, MIS over merge depths",
      IntegratorFamily::Own, "spp",
      {iterations(), params::maxDepth(), heuristic(), sampler(), mergeRadius("one pixel footprint at the median visible distance"),
       mergeAlpha()},
      [](const ParamSet& p, const RenderOptions&) {
        BidirectionalOptions o = common(p);
        o.connect = false;
        o.merge = true;
        return std::make_unique<VertexConnectionMerging>(o, "bpm");
      },
      resolveMergeRadius);
}

IntegratorEntry vcmEntry() {
  return IntegratorEntry(
      "vcm", "vertex connection and merging (Georgiev et al. 2012): bdpt and bpm under one MIS",
      IntegratorFamily::Own, "spp",
      {iterations(), params::maxDepth(), heuristic(), sampler(),
       mergeRadius("three pixel footprints at the median visible distance (one with --direct-merges on)"), mergeAlpha(),
       directMerges()},
      [](const ParamSet& p, const RenderOptions&) {
        BidirectionalOptions o = common(p);
        o.merge = true;
        o.directMerges = p.choice("direct_merges") == "on";
        return std::make_unique<VertexConnectionMerging>(o, "vcm");
      },
      resolveMergeRadius);
}


}  // namespace pl
