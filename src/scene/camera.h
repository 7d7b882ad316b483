// Pinhole camera as glTF defines it: looks down its local −Z with +Y up; yfov is the full
// vertical field of view in radians.
//
// Seen from the light's side (light tracing, bidirectional methods) the camera is an emitter of
// importance. With the film at distance 1 in front of the pinhole, of area
// A = (2 tan(yfov/2))² · aspect, the importance of a ray at angle θ from the view axis is
// We = 1/(A cos⁴θ) inside the film and 0 outside: then ∫ We cosθ dω over the film is 1, so a
// measurement with We is the film's mean radiance, and pixel j's value is W·H times the part of
// it that lands in pixel j (pbrt-v3 §16.1.1, Veach 1997 §8.1).
#pragma once
#include <string>

#include "core/common.h"

namespace pl {

// A connection from a scene point to the camera (Camera::sampleWi).
struct CameraSample {
  Vec2 raster;          // film position in pixels, (0, 0) the top-left corner
  Vec3 wi;              // unit, from the scene point towards the pinhole
  float distance = 0;   // to the pinhole
  float We = 0;         // importance of the ray from the pinhole to the point
  float pdf = 0;        // solid-angle density of wi seen from the point: d²/cosθ (the pinhole is a delta position)
  float pdfDir = 0;     // density with which generateRay() emits −wi: 1/(A cos³θ), as pdfWe()
};

struct Camera {
  Vec3 position{0.0f};
  Vec3 right{1, 0, 0}, up{0, 1, 0}, forward{0, 0, -1};  // orthonormal, world space
  float yfov = 0.8f;
  float aspectRatio = 0.0f;  // width/height from the file; 0 when the file does not say

  // Ray through film position (x, y) in pixels, (0, 0) the top-left corner of the image.
  Ray generateRay(float x, float y, int width, int height) const {
    return generateRay(x, y, width, height, std::tan(0.5f * yfov));
  }
  // The same with tan(yfov/2) computed once by the caller, not once per camera ray.
  Ray generateRay(float x, float y, int width, int height, float tanHalf) const {
    float aspect = float(width) / float(height);
    float sx = (2.0f * x / width - 1.0f) * tanHalf * aspect;
    float sy = (1.0f - 2.0f * y / height) * tanHalf;  // row 0 at the top
    Vec3 d = glm::normalize(forward + sx * right + sy * up);
    return Ray{position, d};
  }

  // Film area at distance 1 from the pinhole.
  float filmArea(int width, int height) const { return filmArea(width, height, std::tan(0.5f * yfov)); }

  // Where the ray leaving the pinhole in direction d (unit) meets the film, in pixels; false when
  // it misses the film (behind the camera, or outside the image). The inverse of generateRay().
  bool raster(const Vec3& d, int width, int height, Vec2* r) const {
    return raster(d, width, height, std::tan(0.5f * yfov), r);
  }

  // Importance of the ray leaving the pinhole in direction d (unit): 1/(A cos⁴θ) on the film, 0
  // elsewhere.
  float We(const Vec3& d, int width, int height) const {
    Vec2 r;
    if (!raster(d, width, height, &r)) return 0.0f;
    float c = glm::dot(d, forward);
    return 1.0f / (filmArea(width, height) * c * c * c * c);
  }

  // Densities with which generateRay() at a uniform film position emits direction d: the
  // position is the pinhole (a delta: 1), the direction 1/(A cos³θ) on the film.
  void pdfWe(const Vec3& d, int width, int height, float* pdfPos, float* pdfDir) const {
    pdfWe(d, width, height, std::tan(0.5f * yfov), pdfPos, pdfDir);
  }
  void pdfWe(const Vec3& d, int width, int height, float tanHalf, float* pdfPos, float* pdfDir) const {
    *pdfPos = 1.0f;
    Vec2 r;
    *pdfDir = raster(d, width, height, tanHalf, &r) ? generatedPdfDir(d, width, height, tanHalf) : 0.0f;
  }
  // The direction density 1/(A cos³θ) of a ray generateRay() made, without pdfWe's test that it
  // meets the film [0, W) × [0, H): a jittered position x + u (u < 1) of the last column or row
  // can round to W or H in float (at 512 pixels when u is within 2⁻¹⁶ of 1), and the test
  // leaves that edge out. A density of 0 there turned a bidirectional camera subpath's weights
  // into NaN (the sample was discarded: 2 in 32 iterations of bpm at 512², seed 1).
  float generatedPdfDir(const Vec3& d, int width, int height, float tanHalf) const {
    float c = glm::dot(d, forward);
    return 1.0f / (filmArea(width, height, tanHalf) * c * c * c);
  }

  // The connection from scene point p to the pinhole: the pixel it lands in, We, and the
  // density d²/cosθ that turns We into a contribution β f |cos| We / pdf, with pdfWe's direction
  // density beside them (bidirectional MIS needs both). False when p is not in view. A light
  // path makes one such connection per vertex: its callers pass tan(yfov/2) (the overload below).
  bool sampleWi(const Vec3& p, int width, int height, CameraSample* s) const {
    return sampleWi(p, width, height, std::tan(0.5f * yfov), s);
  }
  // pdfWe and sampleWi with tan(yfov/2) computed once by the caller (Scene::cameraTanHalf).
  bool sampleWi(const Vec3& p, int width, int height, float tanHalf, CameraSample* s) const {
    Vec3 toCamera = position - p;
    float d2 = glm::dot(toCamera, toCamera);
    if (!(d2 > 0)) return false;
    s->distance = std::sqrt(d2);
    s->wi = toCamera / s->distance;
    Vec3 d = -s->wi;
    if (!raster(d, width, height, tanHalf, &s->raster)) return false;
    float c = glm::dot(d, forward);
    const float area = filmArea(width, height, tanHalf);
    s->We = 1.0f / (area * c * c * c * c);
    s->pdfDir = 1.0f / (area * c * c * c);
    s->pdf = d2 / c;
    return true;
  }

 private:
  static float filmArea(int width, int height, float tanHalf) {
    return 4.0f * tanHalf * tanHalf * (float(width) / float(height));
  }
  bool raster(const Vec3& d, int width, int height, float tanHalf, Vec2* r) const {
    float z = glm::dot(d, forward);
    if (!(z > 0)) return false;
    float aspect = float(width) / float(height);
    float sx = glm::dot(d, right) / z, sy = glm::dot(d, up) / z;
    float x = (sx / (tanHalf * aspect) + 1.0f) * 0.5f * width;
    float y = (1.0f - sy / tanHalf) * 0.5f * height;
    if (!(x >= 0 && x < width && y >= 0 && y < height)) return false;
    *r = Vec2(x, y);
    return true;
  }
};

// The view a file without a camera is rendered from: a three-quarter view, from the front
// (+Z, the side glTF assets face), 45° to the right (+X) and 30° above the horizon (+Y up),
// looking at the centre of the bounding sphere (center, radius); yfov 40°. Other angles (radians)
// orbit the same centre (--orbit): azimuth from +Z towards +X, elevation above the horizon,
// strictly between −90° and 90°. The distance R / sin(h), with h the smaller of the vertical and
// horizontal half-angles for image aspect `aspect` (width/height), puts the whole sphere inside
// the view cone of half-angle h, which the image's frustum contains: nothing is cut off at any
// aspect. aspectRatio stays 0, so the image keeps whatever size --width/--height give it.
inline Camera automaticCamera(const Vec3& center, float radius, float aspect, float azimuth = 0.78539816f,
                              float elevation = 0.52359878f, float yfov = 0.69813170f) {
  if (!(radius > 0) || !std::isfinite(radius)) radius = 1.0f;
  if (!(aspect > 0) || !std::isfinite(aspect)) aspect = 1.0f;
  const float halfV = 0.5f * yfov, halfH = std::atan(std::tan(halfV) * aspect);
  const float distance = radius / std::sin(std::min(halfV, halfH));
  const Vec3 away(std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth));
  Camera c;
  c.yfov = yfov;
  c.position = center + distance * away;
  c.forward = -away;
  c.right = glm::normalize(glm::cross(c.forward, Vec3(0, 1, 0)));
  c.up = glm::cross(c.right, c.forward);
  return c;
}

// A pinhole at `from` looking at `at`, `up` giving the image's vertical (it need only not be
// parallel to the view direction); yfov the full vertical field of view (radians).
inline Camera lookAtCamera(const Vec3& from, const Vec3& at, const Vec3& up, float yfov) {
  Camera c;
  c.yfov = yfov;
  c.position = from;
  c.forward = glm::normalize(at - from);
  c.right = glm::normalize(glm::cross(c.forward, up));
  c.up = glm::cross(c.right, c.forward);
  return c;
}

// A view given on the command line instead of the file's camera: --look-from/--look-at/--up,
// --orbit AZ,EL around the automatic framing, and --fov (degrees, vertical) with either or alone
// (then on the file's camera, or the automatic view).
struct CameraView {
  enum class Kind { File, LookAt, Orbit } kind = Kind::File;
  Vec3 from{0.0f}, at{0.0f}, up{0, 1, 0};
  float azimuth = 45, elevation = 30;  // degrees (Orbit)
  float fov = 0;                       // degrees; 0: the camera's own (40° for the automatic views)
  bool given() const { return kind != Kind::File || fov > 0; }
  // As the image metadata records it: the flags that make the same view.
  std::string describe() const {
    auto v3 = [](const Vec3& v) { return formatNumber(v.x) + "," + formatNumber(v.y) + "," + formatNumber(v.z); };
    std::string s = kind == Kind::LookAt  ? "--look-from " + v3(from) + " --look-at " + v3(at) + " --up " + v3(up)
                    : kind == Kind::Orbit ? "--orbit " + formatNumber(azimuth) + "," + formatNumber(elevation)
                                          : "";
    if (fov > 0) s += (s.empty() ? "" : " ") + std::string("--fov ") + formatNumber(fov);
    return s;
  }
};

}  // namespace pl
