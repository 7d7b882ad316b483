#include "render/visible_probe.h"

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
        if (!hit.bsdf->isDelta()) {
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

}  // namespace pl
