#include "render/visible_probe.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace pl {

std::vector<ProbePoint> probeVisiblePoints(const Scene& scene, int width, int height, int n) {
  const Camera& c = scene.camera();
  std::vector<ProbePoint> points;
  points.reserve(size_t(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      Rng rng = Rng::keyed(0x70726f6265ULL, uint64_t(j) * n + i, 0);  // "probe"
      Ray ray = c.generateRay((i + 0.5f) * width / n, (j + 0.5f) * height / n, width, height);
      float travelled = 0;
      for (int depth = 0; depth < 16; ++depth) {
        SurfaceHit hit;
        if (!scene.intersect(ray, &hit)) break;
        travelled += hit.t;
        if (!hit.bsdf->isSpecular()) {
          points.push_back({hit, -ray.d, travelled});
          break;
        }
        BSDFSample s;
        Vec3 wo = hit.shading.toLocal(-ray.d);
        if (!hit.bsdf->sample(wo, bsdfContext(hit), Vec2(rng.uniform(), rng.uniform()), rng.uniform(), &s))
          break;
        ray = scene.spawnRay(hit, hit.shading.toWorld(s.wi));
      }
    }
  return points;
}

EmissionTarget visibleEmissionTarget(const Scene& scene, int width, int height, float margin) {
  const std::vector<ProbePoint> points = probeVisiblePoints(scene, width, height, 64);
  EmissionTarget target;
  if (points.empty()) return target;
  Vec3 lo(INFINITY), hi(-INFINITY);
  for (const ProbePoint& p : points) lo = glm::min(lo, p.hit.p), hi = glm::max(hi, p.hit.p);
  const float radius = 1.1f * 0.5f * glm::length(hi - lo) + margin;
  if (radius >= 0.9f * scene.bounds().radius()) return target;  // aiming would gain nothing
  target.center = 0.5f * (lo + hi);
  target.radius = radius;
  return target;
}

DefaultRadius defaultRadius(const Scene& scene, int width, int height) {
  // The distances at which the camera sees the surfaces photons are gathered on.
  const Camera& c = scene.camera();
  std::vector<float> distances;
  for (const ProbePoint& p : probeVisiblePoints(scene, width, height)) distances.push_back(p.distance);
  DefaultRadius r;
  r.visiblePoints = distances.size();
  if (distances.empty()) {
    // Nothing diffuse in view: the distance to the scene's centre, at least its radius.
    r.distance = std::max(glm::length(scene.bounds().center() - c.position), scene.bounds().radius());
  } else {
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    r.distance = distances[distances.size() / 2];
  }
  // A pixel's footprint at that distance (the film spans 2 d tan(fov/2) vertically).
  r.footprint = 2.0f * r.distance * std::tan(0.5f * c.yfov) / float(height);
  r.radius = DefaultRadius::kFootprints * r.footprint;
  if (!(r.radius > 0) || !std::isfinite(r.radius)) r.radius = 1e-3f * std::max(scene.bounds().radius(), 1e-3f);
  return r;
}

}  // namespace pl
