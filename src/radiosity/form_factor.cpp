#include "radiosity/form_factor.h"

#include <algorithm>
#include <cmath>

namespace pl {

float pointToTriangle(const Vec3& x, const Vec3& n, const Vec3 (&triangle)[3]) {
  // Clip against the tangent plane n·(y − x) ≥ 0 (Sutherland–Hodgman; a triangle cut by a plane
  // leaves at most four corners).
  Vec3 polygon[4];
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    const Vec3& a = triangle[k];
    const Vec3& b = triangle[(k + 1) % 3];
    float da = glm::dot(n, a - x), db = glm::dot(n, b - x);
    if (da >= 0) polygon[count++] = a;
    if ((da >= 0) != (db >= 0)) polygon[count++] = a + (b - a) * (da / (da - db));
  }
  if (count < 3) return 0.0f;
  double sum = 0.0;
  for (int k = 0; k < count; ++k) {
    Vec3 r0 = polygon[k] - x, r1 = polygon[(k + 1) % count] - x;
    float l0 = glm::length(r0), l1 = glm::length(r1);
    if (!(l0 > 0) || !(l1 > 0)) continue;  // x on a corner: that edge subtends nothing
    r0 /= l0, r1 /= l1;
    Vec3 c = glm::cross(r0, r1);
    float s = glm::length(c);
    if (!(s > 0)) continue;
    // γ by atan2: acos loses the small angles of far or small patches.
    float gamma = std::atan2(s, glm::dot(r0, r1));
    sum += double(gamma) * glm::dot(n, c) / s;
  }
  return float(std::abs(sum) * kInv2Pi);
}

void subCentroids(const Vec3 (&t)[3], int m, Vec3* points) {
  const Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0];
  int k = 0;
  auto at = [&](float a, float b) { points[k++] = t[0] + (a / m) * e1 + (b / m) * e2; };
  for (int a = 0; a < m; ++a)
    for (int b = 0; a + b <= m - 1; ++b) at(a + 1.0f / 3, b + 1.0f / 3);
  for (int a = 0; a + 1 < m; ++a)
    for (int b = 0; a + b <= m - 2; ++b) at(a + 2.0f / 3, b + 2.0f / 3);
}

namespace {

bool segmentVisible(const Scene& scene, const Vec3& x, const Vec3& nx, const Vec3& y, const Vec3& ny) {
  const float eps = scene.epsilon();
  Vec3 o = x + eps * nx, target = y + eps * ny;
  Vec3 d = target - o;
  float length = glm::length(d);
  if (length <= 2 * eps) return true;
  return !scene.occluded(Ray{o, d / length, 0.0f, length - eps});
}

// Wallace, Elmquist & Haines (1989): the form factor from a point to a disc of area A seen at
// distance r, A cosθx cosθy / (πr² + A), exact on the axis; the point-to-point estimate without
// the "+ A" diverges as r → 0.
float discFormFactor(float area, float cosX, float cosY, float r2) {
  return area * cosX * cosY / (kPi * r2 + area);
}

// All of a patch on or behind the plane of another: the pair exchanges nothing.
bool behind(const Patch& p, const Patch& plane) {
  const float tolerance = 1e-6f * std::max(p.size, plane.size);
  for (const Vec3& v : p.v)
    if (glm::dot(plane.normal, v - plane.centroid) > tolerance) return false;
  return true;
}

// A patch's exposed quadrature points (all 16 of its 4×4 sub-grid unless some are buried).
int exposedPoints(const Patch& p, Vec3* out) {
  Vec3 all[16];
  subCentroids(p.v, 4, all);
  int n = 0;
  for (int k = 0; k < 16; ++k)
    if (p.exposed & (1u << k)) out[n++] = all[k];
  return n;
}

}  // namespace

FormFactorPair formFactors(const Scene& scene, const Patch& i, const Patch& j) {
  FormFactorPair f;
  if (i.exposed == 0 || j.exposed == 0) return f;
  if (behind(j, i) || behind(i, j)) return f;
  const Vec3 between = j.centroid - i.centroid;
  const float r2 = glm::dot(between, between);
  const float largest = std::max(i.size, j.size);
  const bool emitters = !isBlack(i.exitance) || !isBlack(j.exitance);
  // Partly buried patches: points from their exposed part only, and the form factor towards
  // one scaled by its exposed fraction (the rest of it is covered, by what the segments hit).
  // (Point arrays are declared where they are filled: GLM_FORCE_CTOR_INIT zeroes every Vec3,
  // and zeroing unused ones for every pair showed in the form factors' profile.)
  const bool whole = i.exposed == 0xFFFF && j.exposed == 0xFFFF;
  const double scaleIJ = j.exposure(), scaleJI = i.exposure();

  if (r2 > (kNearDistance * largest) * (kNearDistance * largest)) {
    // Far: one point per patch, or four when light starts here.
    const int m = emitters ? 2 : 1, count = m * m;
    Vec3 xs[4], ys[4];
    if (whole) {
      subCentroids(i.v, m, xs);
      subCentroids(j.v, m, ys);
    } else {
      Vec3 exposedI[16], exposedJ[16];
      const int nI = exposedPoints(i, exposedI), nJ = exposedPoints(j, exposedJ);
      for (int k = 0; k < count; ++k) xs[k] = exposedI[(k * nI) / count], ys[k] = exposedJ[(k * nJ) / count];
    }
    double ij = 0, ji = 0;
    for (int k = 0; k < count; ++k) {
      const Vec3& x = xs[k];
      const Vec3& y = ys[(3 * k + 1) % count];  // paired across the patches, not corner to corner
      Vec3 d = y - x;
      float d2 = glm::dot(d, d);
      Vec3 w = d / std::sqrt(d2);
      float cosX = glm::dot(i.normal, w), cosY = -glm::dot(j.normal, w);
      if (cosX <= 0 || cosY <= 0) continue;
      ++f.rays;
      if (!segmentVisible(scene, x, i.normal, y, j.normal)) continue;
      ij += discFormFactor(j.area, cosX, cosY, d2);
      ji += discFormFactor(i.area, cosX, cosY, d2);
    }
    f.ij = float(scaleIJ * ij / count);
    f.ji = float(scaleJI * ji / count);
    return f;
  }

  // Near: 16 points on each side, the closed form from each, the visibility of 16 segments.
  Vec3 xs[16], ys[16];
  int nI = 16, nJ = 16;
  Vec3 allI[16], allJ[16];  // every point, buried or not (partly buried pairs only)
  if (whole) {
    subCentroids(i.v, 4, xs);
    subCentroids(j.v, 4, ys);
  } else {
    nI = exposedPoints(i, xs);
    nJ = exposedPoints(j, ys);
    subCentroids(i.v, 4, allI);
    subCentroids(j.v, 4, allJ);
  }
  // Of a partly buried patch, the closed form counts all that is in front of the receiving
  // point; the exposed share is taken of that part only. The buried part of a floor patch
  // is under the box, behind the plane of the box's own face: from the face, none of what the
  // closed form counts is buried, although a quarter of the patch is.
  auto exposedShare = [](const Vec3& x, const Vec3& n, const Vec3* points, uint16_t exposed) {
    if (exposed == 0xFFFF) return 1.0f;
    int front = 0, visible = 0;
    for (int k = 0; k < 16; ++k)
      if (glm::dot(n, points[k] - x) > 0) ++front, visible += (exposed >> k) & 1;
    return front > 0 ? float(visible) / front : 0.0f;
  };
  double ij = 0, ji = 0;
  for (int k = 0; k < nI; ++k) {
    const Vec3& x = xs[k];
    float fx = pointToTriangle(x, i.normal, j.v);
    // The segment's far end: the k-th point of a fixed permutation of j's points, or the next
    // one in front of x if that one is behind it (a segment into x's own surface would be
    // blocked by it).
    int yk = -1;
    for (int step = 0; step < nJ; ++step) {
      int candidate = (5 * (k + step) + 3) % nJ;
      if (glm::dot(i.normal, ys[candidate] - x) > 0 && glm::dot(j.normal, x - ys[candidate]) > 0) {
        yk = candidate;
        break;
      }
    }
    if (yk < 0) continue;
    // The same segment, from its other end, for F_ji.
    float fy = pointToTriangle(ys[yk], j.normal, i.v);
    if (fx <= 0 && fy <= 0) continue;
    ++f.rays;
    if (!segmentVisible(scene, x, i.normal, ys[yk], j.normal)) continue;
    if (!whole) {
      fx *= exposedShare(x, i.normal, allJ, j.exposed);
      fy *= exposedShare(ys[yk], j.normal, allI, i.exposed);
    }
    ij += fx;
    ji += fy;
  }
  f.ij = float(ij / nI);
  f.ji = float(ji / nI);
  return f;
}

Spectrum directIrradiance(const Scene& scene, const Light& light, const Patch& patch) {
  Vec3 xs[16];
  const int count = exposedPoints(patch, xs);
  if (count == 0) return Spectrum(0.0f);
  const SampledWavelengths& rgb = SampledWavelengths::rgb();
  Spectrum sum(0.0f);
  for (int k = 0; k < count; ++k) {
    const Vec3& x = xs[k];
    LightSample s;
    // Delta lights ignore the sample: one direction, one distance.
    if (!light.sampleLi(x, Vec2(0.5f), rgb, &s)) continue;
    float cosTheta = glm::dot(patch.normal, s.wi);
    if (cosTheta <= 0) continue;
    const float eps = scene.epsilon();
    Ray ray{x + eps * patch.normal, s.wi, 0.0f, std::isinf(s.distance) ? INFINITY : s.distance - eps};
    if (scene.occluded(ray)) continue;
    sum += s.Li * cosTheta;  // E = I cosθ / r² (point, spot), E cosθ (directional)
  }
  return sum / float(count);
}

}  // namespace pl
