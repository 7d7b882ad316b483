// The path tracer's estimator, 16 paths at a time in SIMD lanes (a wavefront, as Mitsuba 3's
// LLVM backend and pbrt-v4's GPU path run theirs). PathIntegrator hands it a batch of rows of camera samples
// when the scene is one it covers; it computes, for each, what PathIntegrator::Li computes, with
// the same random numbers drawn in the same order, so the two agree pixel by pixel up to
// floating-point rounding.
//
// It covers what the common scenes hold: triangle meshes with or without vertex normals;
// Lambertian surfaces of constant colour, mirrors of constant reflectance, smooth glass without
// dispersion; one-sided or two-sided area lights of constant radiance; RGB, independent samples.
// unsupported() says what else a scene has; the scalar path tracer renders those.
#pragma once
#include <string>
#include <vector>

#include "core/lanes_isa.h"
#include "render/integrator.h"

namespace pl {

class PathLanes {
 public:
  // Empty if the lanes can render `scene`; otherwise what they cannot (one line).
  static std::string unsupported(const Scene& scene);
  // Throws pl::Error where unsupported() says why.
  explicit PathLanes(const Scene& scene);
  PathLanes(const PathLanes&) = delete;
  PathLanes& operator=(const PathLanes&) = delete;

  // samples[k].L for n camera samples (any n: a batch of rows), paths of at most maxDepth bounces.
  // Each sample's sampler must draw independent numbers (no Sobol' slots).
  void trace(PixelIntegrator::CameraSample* samples, int n, int maxDepth) const;

  // What the lanes read at a hit, one cache line per triangle: the hit's first memory access,
  // so kept small.
  struct alignas(64) Triangle {
    Vec3 p0, p1, p2;  // Scene::trianglePositions
    Vec3 ng;          // geometric normal (SurfaceHit::ng)
    int32_t normals;  // its vertex normals' index in normals_, or −1: flat
    int32_t material; // index into surfaces_ (= Scene::materials())
    int32_t light;    // index into Scene::lights() (an area light), or −1
    int32_t unused;   // (16 words: the lanes read a record as one vector)
  };
  // A smooth triangle's vertex normals as stored (Scene::triangleNormals), one cache line each.
  struct alignas(64) Normals {
    Vec3 n0, n1, n2;
  };
  static constexpr int32_t kLambertian = 0, kMirror = 1, kGlass = 2;  // Surface::kind
  struct Surface {
    int32_t kind;
    Vec3 color;  // Lambertian ρ, or the mirror's F0
    float eta;   // glass: η_inside / η_outside
  };
  struct Emitter {  // an AreaLight's data
    Vec3 p0, p1, p2, n, Le;
    float area, pmf;
    int32_t twoSided;
  };

 private:
  const Scene& scene_;
  std::vector<Triangle> triangles_;  // by triangle number (Scene::trianglePositions)
  std::vector<uint32_t> firstTriangle_;  // by Embree geometry (Scene::geometryFirstTriangles)
  std::vector<Normals> normals_;
  std::vector<Surface> surfaces_;
  std::vector<Emitter> emitters_;  // by index in Scene::lights()
  lanes::Isa isa_;                 // the kernel's copy that runs (lanes::bestIsa, once per render)
};

}  // namespace pl
