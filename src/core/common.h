// Basic types shared by every part of the renderer.
#pragma once
#include <glm/glm.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
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

inline float luminance(const Spectrum& s) { return 0.2126f * s.r + 0.7152f * s.g + 0.0722f * s.b; }
inline float average(const Spectrum& s) { return (s.r + s.g + s.b) / 3.0f; }
inline float maxComponent(const Spectrum& s) { return std::max(s.r, std::max(s.g, s.b)); }
inline bool isBlack(const Spectrum& s) { return s.r == 0.0f && s.g == 0.0f && s.b == 0.0f; }
inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A number as metadata and CSV files store it: shortest form that round-trips a float.
inline std::string formatNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct Ray {
  Vec3 o, d;  // d is unit length
  float tmin = 0.0f, tmax = INFINITY;
};

}  // namespace pl
