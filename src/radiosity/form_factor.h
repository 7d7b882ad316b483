// Form factors between patches: F_ij, the fraction of the flux leaving patch i (diffusely) that
// arrives at patch j,
//   F_ij = (1/A_i) ∫_Ai ∫_Aj cosθi cosθj / (π r²) · V(x, y) dy dx,
// with reciprocity A_i F_ij = A_j F_ji and Σ_j F_ij = 1 in a closed scene.
#pragma once
#include "radiosity/patch_mesh.h"

namespace pl {

// Unoccluded form factor from a differential area at x (unit normal n) to a triangle, in closed
// form (Lambert 1760; Baum, Rushmeier & Winget 1989):
//   F = (1/2π) |Σ_k γ_k n·(R_k × R_{k+1}) / |R_k × R_{k+1}||,   R_k = v_k − x,
// γ_k the angle between R_k and R_{k+1}. The part of the triangle behind x's tangent plane is
// clipped off first (it receives nothing from x's front). It is exact however close the
// triangle is, which a point-to-point estimate cos·cos·A/(πr²) is not.
float pointToTriangle(const Vec3& x, const Vec3& n, const Vec3 (&triangle)[3]);

// The form factors of one pair both ways, with the visibility of the same segments.
struct FormFactorPair {
  float ij = 0.0f, ji = 0.0f;
  int rays = 0;  // visibility rays cast
};

// How the double integral is estimated (fixed, deterministic quadrature; no random numbers):
//  - pairs closer than kNearDistance × the larger patch: 16 points on each patch (the
//    centroids of a 4×4 sub-grid), the closed form above from each point to the other patch,
//    times the visibility of a segment from that point to a point of the other patch;
//  - farther pairs: the centroids, Wallace's disc estimate A cosθi cosθj / (πr² + A) (exact for
//    coaxial discs; within 1% of the closed form beyond 4 patch sizes, see tests) and one
//    visibility ray; 4 points and 4 rays when either patch emits, where most of the light
//    starts and shadows are sharpest.
// Shadow boundaries are resolved to the patch (or a quarter of it), the method's known limit:
// smaller patches resolve them better. A partly buried patch (Patch::exposed) contributes only
// its exposed points, and the form factor towards it is scaled by its exposed fraction.
constexpr float kNearDistance = 4.0f;
FormFactorPair formFactors(const Scene& scene, const Patch& i, const Patch& j);

// Irradiance E (W/m²) a delta light (point, spot, Warn, directional) gives the front of a patch,
// averaged over the exposed points of its 4×4 sub-grid, each with a shadow ray.
Spectrum directIrradiance(const Scene& scene, const Light& light, const Patch& patch);

// The centroids of a triangle's m×m sub-grid, the quadrature points above (m² of them).
void subCentroids(const Vec3 (&triangle)[3], int m, Vec3* points);

}  // namespace pl
