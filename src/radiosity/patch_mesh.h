// The finite elements of classic radiosity (Goral, Torrance, Greenberg, Battaile 1984; Cohen &
// Wallace 1993): the scene's surfaces cut into small planar patches, each with one radiosity B
// (W/m², the flux density leaving it), one diffuse reflectance ρ and one exitance M = π·Le of its
// own. Every scene triangle with n = ⌈longest edge / patch size⌉ is split into n² congruent
// sub-triangles on a regular barycentric grid, so that a hit's patch follows from its
// barycentric coordinates without a search.
//
// Patches are one-sided, as in the method's literature: a patch receives and leaves light on its
// front only. The front is the emitting face of an emitter (its counter-clockwise face, or both
// faces when glTF doubleSided), otherwise the side the shading normal at its centroid points to.
// A doubleSided material gets one patch per face. The back of a one-sided patch is black.
#pragma once
#include <string>
#include <vector>

#include "scene/scene.h"

namespace pl {

struct Patch {
  Vec3 v[3];             // corners (world space), in the scene triangle's order
  Vec3 normal;           // unit, the front
  Vec3 centroid;
  float area = 0.0f;
  float size = 0.0f;     // longest edge
  Spectrum reflectance;  // ρ: the diffuse albedo at the centroid (0 for non-diffuse materials)
  Spectrum exitance;     // M = π·Le, emitted from the front
  uint32_t primitive = 0;
  uint32_t corner[3];    // shared vertices (smooth display), see PatchMesh::vertexCount
  // Which of the patch's 16 quadrature points (radiosity/form_factor.h) are exposed, bit k for
  // point k: a point inside a closed object (the floor under a box standing on it) is not.
  // The patch's B is then the mean over its exposed part, the part anyone can see, instead of
  // being dragged down by the buried part, which darkens the floor around every object
  // standing on it when the mesh ignores the contact line (Baum et al. 1991 split the mesh
  // there; this only leaves the buried points out).
  uint16_t exposed = 0xFFFF;
  float exposure() const { return float(__builtin_popcount(exposed)) / 16.0f; }
};

class PatchMesh {
 public:
  // patchSize > 0 (metres).
  PatchMesh(const Scene& scene, float patchSize);

  // How many patches `patchSize` makes, and the patch size whose count is closest to `budget`
  // without exceeding it (bisection; the count only grows as the size shrinks).
  static size_t count(const Scene& scene, float patchSize);
  static float patchSizeFor(const Scene& scene, size_t budget);

  const std::vector<Patch>& patches() const { return patches_; }
  size_t size() const { return patches_.size(); }
  float patchSize() const { return patchSize_; }
  // Materials that are not diffuse (mirror, glass, glossy): black in the method. Names, once each.
  const std::vector<std::string>& nonDiffuseMaterials() const { return nonDiffuse_; }

  // The patch at barycentric (b1, b2) of `primitive` on the face that `w` (world, pointing away
  // from the surface) leaves from, or −1 when that face has none (the back of a one-sided
  // surface). `weights` (may be null) receives the point's barycentric weights on the patch's
  // three corners.
  int locate(uint32_t primitive, const Vec2& b, const Vec3& w, Vec3* weights = nullptr) const;

  // Shared vertices: corners at one position on patches of one plane facing one way with one
  // material are one vertex, so that smooth shading interpolates within a surface and never
  // across a crease or a material boundary (a wall's radiosity does not bleed into the light).
  size_t vertexCount() const { return vertexCount_; }
  // Vertex radiosities: each the area-weighted mean of its patches' values.
  std::vector<Spectrum> vertexValues(const std::vector<Spectrum>& patchValues) const;

 private:
  // Marks the quadrature points buried inside closed objects (Patch::exposed).
  void findBuriedPoints(const Scene& scene);

  struct Faces {
    int first[2] = {-1, -1};  // first patch of the front and the back face (−1: none)
    Vec3 normal;              // the front face's normal
    int n = 0;                // subdivisions per edge
  };
  std::vector<Patch> patches_;
  std::vector<Faces> faces_;  // per scene triangle
  std::vector<std::string> nonDiffuse_;
  size_t vertexCount_ = 0;
  float patchSize_ = 0.0f;
};

}  // namespace pl
