// Basic types shared by every part of the renderer.
#pragma once
#include <glm/glm.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pl {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Mat4 = glm::mat4;
// RGB radiometric quantity (radiance, flux, reflectance...) in linear sRGB primaries.
using Spectrum = glm::vec3;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 1.0f / kPi;
constexpr float kInv2Pi = 1.0f / (2.0f * kPi);
constexpr float kInv4Pi = 1.0f / (4.0f * kPi);
// Offset for spawning rays off a surface, relative to the scene's scale (Scene::epsilon()).
constexpr float kRayEpsilonScale = 1e-5f;

// Every user-facing failure (bad file, bad option) is an Error: main() prints what() on one
// line and exits 1.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// For the few tiny functions on every path vertex (frame changes, sampling warps) that GCC's
// link-time inliner otherwise leaves as calls once the unit grows.
#define PL_HOT_INLINE inline __attribute__((always_inline))

inline float luminance(const Spectrum& s) { return 0.2126f * s.r + 0.7152f * s.g + 0.0722f * s.b; }
inline float average(const Spectrum& s) { return (s.r + s.g + s.b) / 3.0f; }
inline float maxComponent(const Spectrum& s) { return std::max(s.r, std::max(s.g, s.b)); }
inline bool isBlack(const Spectrum& s) { return s.r == 0.0f && s.g == 0.0f && s.b == 0.0f; }
// x − x is 0 for finite x and NaN for ±inf or NaN: one branch-free test for all three (this
// guards every photon bounce and path vertex).
inline bool isFinite(const Vec3& v) { return (v.x - v.x) + (v.y - v.y) + (v.z - v.z) == 0.0f; }

// Branch-free `c ? a : b` and `c ? −x : x` for floats. Photon and path sampling branch on
// random numbers (which quarter turn, which half of the square, which face); GCC compiles a
// float `?:` to a branch, and such a branch mispredicts half the time, ~20 cycles each.
// Valgrind's branch simulator counted 11 mispredictions per photon path in our code before
// these were used there (docs: explanation/performance.md).
inline float select(bool c, float a, float b) {
  uint32_t ua, ub, mask = 0u - uint32_t(c);
  std::memcpy(&ua, &a, 4);
  std::memcpy(&ub, &b, 4);
  uint32_t r = (ua & mask) | (ub & ~mask);
  float x;
  std::memcpy(&x, &r, 4);
  return x;
}
inline float negateIf(bool c, float x) {
  uint32_t u;
  std::memcpy(&u, &x, 4);
  u ^= uint32_t(c) << 31;
  std::memcpy(&x, &u, 4);
  return x;
}

// A number as metadata and CSV files store it: shortest form that round-trips a float.
inline std::string formatNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// A fraction as people read it: 0.4854 → "48.5%".
inline std::string percentText(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f%%", 100.0 * fraction);
  return buf;
}

struct Ray {
  Vec3 o, d;  // d is unit length
  float tmin = 0.0f, tmax = INFINITY;
};

}  // namespace pl
