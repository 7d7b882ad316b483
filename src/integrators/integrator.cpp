#include "integrators/integrator.h"

#include "integrators/direct.h"
#include "integrators/path.h"
#include "integrators/photon.h"
#include "integrators/whitted.h"

namespace pl {

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& options) {
  if (name == "direct") return std::make_unique<DirectIntegrator>();
  if (name == "whitted") return std::make_unique<WhittedIntegrator>(options.maxDepth);
  if (name == "path") return std::make_unique<PathIntegrator>(options.maxDepth);
  if (name == "photon") return std::make_unique<PhotonIntegrator>(options);
  throw Error("--integrator: unknown integrator '" + name + "' (" + integratorList() + ")");
}

std::vector<std::string> integratorNames() { return {"direct", "whitted", "path", "photon", "ppm", "sppm", "pppm"}; }

std::string integratorList() {
  std::string s;
  for (auto& n : integratorNames()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

Spectrum estimateDirect(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, Rng& rng, bool mis) {
  const AliasTable& dist = scene.lightDistribution();
  if (dist.size() == 0 || dist.total() <= 0) return Spectrum(0.0f);
  float pmf;
  size_t index = dist.sample(rng.uniform(), &pmf);
  const Light& light = *scene.lights()[index];
  Vec2 u(rng.uniform(), rng.uniform());
  LightSample ls;
  if (!light.sampleLi(hit.p, u, &ls)) return Spectrum(0.0f);
  Vec3 wi = hit.shading.toLocal(ls.wi);
  Spectrum f = hit.bsdf->eval(woLocal, wi, hit.uv);
  if (isBlack(f)) return Spectrum(0.0f);
  // A light below the geometric surface cannot reach it, whatever the shading normal says.
  if (glm::dot(ls.wi, hit.ng) * glm::dot(hit.shading.toWorld(woLocal), hit.ng) <= 0) return Spectrum(0.0f);
  if (!scene.visible(hit, ls.wi, ls.distance)) return Spectrum(0.0f);
  float lightPdf = pmf * ls.pdf;
  float weight = 1.0f;
  if (mis && !light.isDelta()) weight = powerHeuristic(lightPdf, hit.bsdf->pdf(woLocal, wi, hit.uv));
  return f * ls.Li * (std::abs(wi.z) * weight / lightPdf);
}

}  // namespace pl
