#include "spectral/cie.h"

#include <cmath>

namespace pl {

namespace {
inline float lerpTable(const float* table, float lambda) {
  float x = lambda - kLambdaMin;
  if (!(x >= 0.0f) || x > float(kCieSamples - 1)) return 0.0f;
  int i = std::min(int(x), kCieSamples - 2);
  float t = x - float(i);
  return (1.0f - t) * table[i] + t * table[i + 1];
}
}  // namespace

Vec3 cieXYZ(float lambda) { return Vec3(lerpTable(kCieX, lambda), lerpTable(kCieY, lambda), lerpTable(kCieZ, lambda)); }
float d65(float lambda) { return lerpTable(kD65, lambda); }

// IEC 61966-2-1 (sRGB), D65 white; the two matrices are each other's inverse to 1e-7.
Vec3 XYZToRGB(const Vec3& c) {
  return Vec3(3.2404542f * c.x - 1.5371385f * c.y - 0.4985314f * c.z,
              -0.9692660f * c.x + 1.8760108f * c.y + 0.0415560f * c.z,
              0.0556434f * c.x - 0.2040259f * c.y + 1.0572252f * c.z);
}

Vec3 RGBToXYZ(const Vec3& c) {
  return Vec3(0.4124564f * c.x + 0.3575761f * c.y + 0.1804375f * c.z,
              0.2126729f * c.x + 0.7151522f * c.y + 0.0721750f * c.z,
              0.0193339f * c.x + 0.1191920f * c.y + 0.9503041f * c.z);
}

double planck(double lambdaNm, double T) {
  const double h = 6.62607015e-34, c = 2.99792458e8, k = 1.380649e-23;
  double l = lambdaNm * 1e-9;
  return 2.0 * h * c * c / (std::pow(l, 5) * std::expm1(h * c / (l * k * T)));
}

}  // namespace pl
